"""Builds fretbuzz._core through the project's CMake build (see pyproject.toml for why).

The extension is the CMake target fretbuzz_python; this build_ext configures a private build
directory for the running interpreter, builds that one target and copies the module where
setuptools expects it. Environment: CMAKE_BUILD_PARALLEL_LEVEL (default 2) and, when ccache
is installed, it is used as the compiler launcher. FRETBUZZ_PREBUILT_CORE=PATH installs an
already built fretbuzz._core instead (the test suite's pip test uses the one its build made,
for the same interpreter, to stay fast on small machines).
"""
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class Progress:
    """Lines on the terminal while CMake builds: pip keeps a build's output to itself (it shows
    it with -v, or when the build fails), and the C++ library takes minutes to compile. Written
    to /dev/tty when there is one, else nowhere (the lines still go to pip's log)."""

    def __init__(self):
        try:
            self.tty = open("/dev/tty", "w")
        except OSError:
            self.tty = None

    def say(self, text, end="\n"):
        if self.tty is not None:
            self.tty.write("\r" + text + end)
            self.tty.flush()

    def close(self):
        if self.tty is not None:
            self.tty.close()


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        prebuilt = os.environ.get("FRETBUZZ_PREBUILT_CORE")
        if prebuilt:
            shutil.copyfile(prebuilt, target)
            return
        build_dir = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        configure = ["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                     f"-DPython_EXECUTABLE={sys.executable}", "-DFRETBUZZ_BUILD_TESTS=OFF",
                     "-DFRETBUZZ_BUILD_BENCH=OFF"]
        if shutil.which("ccache"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        progress = Progress()
        try:
            progress.say("fretbuzz: configuring the C++ build (CMake)")
            subprocess.run(configure, check=True)
            jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
            progress.say(f"fretbuzz: compiling the C++ library and the extension on {jobs} cores: 10 to 15 minutes on "
                         "two (less with ccache); `pip install -v` shows the compiler's lines")
            build = subprocess.Popen(["cmake", "--build", build_dir, "--target", "fretbuzz_python", "-j", jobs],
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            for line in build.stdout:
                sys.stdout.write(line)  # pip's log
                done = re.match(r"\[\s*(\d+)%\]", line)
                if done:
                    progress.say(f"fretbuzz: building: {done.group(1)}%", end="")
            if build.wait() != 0:
                raise subprocess.CalledProcessError(build.returncode, build.args)
            progress.say("fretbuzz: building: done")
        finally:
            progress.close()
        package = os.path.join(build_dir, "python", "module", "fretbuzz")
        built = [name for name in os.listdir(package) if name.startswith("_core.") and name.endswith(".so")]
        if len(built) != 1:
            raise RuntimeError(f"expected one _core module in {package}, found {built}")
        shutil.copyfile(os.path.join(package, built[0]), target)


setup(ext_modules=[CMakeExtension("fretbuzz._core")], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": "build-python"}})
