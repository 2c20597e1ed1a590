"""The studio and the bench under attack and by accident (issue 50): an instrument's name
stays one folder in the current folder; a request body is never held past 16 KB however it is
sent, and JSON nested deep is a 422; exposed mode needs its token and keeps the Host
allowlist; one studio per study folder, a map visible only when whole, old maps pruned on
request; the server dies with the command and leaves no script behind; Ctrl-C on any thread
never aborts; Python arguments name their field and range; digits are ASCII digits; a full
disk during an export is a JSON 507 with no temporary file left."""
import asyncio
import errno
import http.client
import json
import os
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import fretbuzz
from fretbuzz import studio as studio_package
from fretbuzz.studio import app as studio_app
from fretbuzz.studio import study as study_module
from test_studio import RunningStudio, client_at, quick_bench, wait_for

CLI = os.environ.get("FRETBUZZ_CLI")
QUICK_ARGS = ["--ensemble", "2", "--fs", "3e5", "--duration", "0.05"]
MIB = 1024 * 1024


def peak_kib(pid):
    """The process's peak resident memory so far (VmHWM), KiB."""
    with open(f"/proc/{pid}/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmHWM:"))


def alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def bass_neck_text(name="bass-neck"):
    return fretbuzz.Bench("bass-neck").instrument.source_text.replace('name = "bass-neck"', f'name = "{name}"', 1)


class ServedStudio:
    """A studio in a process of its own: `python3 -m fretbuzz.studio`, or the fretbuzz program
    (cli=True, the server then being its child)."""

    def __init__(self, *args, cli=False, instrument="bass-neck", env=None, cwd=None):
        command = [CLI, "studio"] if cli else [sys.executable, "-m", "fretbuzz.studio"]
        self.process = subprocess.Popen(command + [instrument, "--port", "0", *QUICK_ARGS, *args],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                        env=env, cwd=cwd, start_new_session=True)
        self.line, found = "", None
        while found is None:  # the address, after what the studio says first
            line = self.process.stdout.readline()
            self.line += line
            found = re.search(r"http://\S+?:(\d+)/(\?token=([A-Za-z0-9_-]+))?", line)
            if not line:
                break
        if found is None:
            self.process.kill()
            raise AssertionError(self.line + self.process.communicate(timeout=30)[1])
        self.port, self.token = int(found.group(1)), found.group(3)
        def answers():  # uvicorn has its Ctrl-C handler once it answers
            try:
                return self.request("GET", "/api/state")[0] in (200, 401)
            except OSError:
                return False
        wait_for(answers, 30, "the studio to answer")
        self.server_pid = self.process.pid
        if cli:
            with open(f"/proc/{self.process.pid}/task/{self.process.pid}/children") as f:
                self.server_pid = int(f.read().split()[0])

    def request(self, method, path, body=None, headers=None):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=60)
        try:
            connection.request(method, path, body=body, headers=headers or {})
            response = connection.getresponse()
            return response.status, response.read()
        finally:
            connection.close()

    def first_map_done(self):
        def done():
            return json.loads(self.request("GET", "/api/state")[1])["done"] is not None
        wait_for(done, 120, "the first map")

    def stop(self):
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGINT)
        out, err = self.process.communicate(timeout=60)
        return self.process.returncode, err


class HostileNameTest(unittest.TestCase):
    """`name` is one plain path component, refused with the key named (exit 2 from the commands)."""

    BAD = ("x/../../../../victim-home", "", "/", "..", "<script>", ".hidden", "a..b", "tab\\there")

    def test_a_name_that_leaves_its_folder_is_refused_naming_the_key(self):
        for name in self.BAD:
            with self.assertRaises(fretbuzz.InputError, msg=name) as e:
                fretbuzz.Bench.from_text(bass_neck_text(name))
            self.assertIn("name = ", str(e.exception))
            self.assertIn("letters (a-z, A-Z), digits", str(e.exception))
        self.assertEqual(fretbuzz.Bench.from_text(bass_neck_text("My Bass 2.0")).instrument.name, "My Bass 2.0")

    def test_the_default_study_folder_is_in_the_current_folder(self):
        self.assertEqual(studio_package.default_folder("My Bass 2.0"), os.path.join(os.getcwd(), "studio-My Bass 2.0"))
        for name in ("x/../../y", "/abs"):
            with self.assertRaises(fretbuzz.InputError):
                studio_package.default_folder(name)

    @unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
    def test_the_commands_refuse_it_with_exit_2_and_write_nothing(self):
        with tempfile.TemporaryDirectory() as d:
            work = os.path.join(d, "a", "b", "c", "d", "work")
            os.makedirs(work)
            path = os.path.join(work, "hostile.toml")
            with open(path, "w") as f:
                f.write(bass_neck_text("x/../../../../victim-home"))
            before = sorted(os.walk(d))
            for command in (["studio", path, "--port", "0"], ["setup", path, "--strings", "G", "--out", "map"]):
                run = subprocess.run([CLI, *command], capture_output=True, text=True, timeout=120, cwd=work)
                self.assertEqual(run.returncode, 2, run.stderr)
                self.assertIn("name = \"x/../../../../victim-home\"", run.stderr)
            self.assertEqual(sorted(os.walk(d)), before)


class BodyLimitTest(unittest.TestCase):
    """No more than 16 KB of a body is ever taken in, however it is sent."""

    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="fretbuzz-studio-test-")
        cls.studio = ServedStudio("--study", os.path.join(cls.dir, "study"))
        cls.studio.first_map_done()

    @classmethod
    def tearDownClass(cls):
        cls.studio.stop()
        shutil.rmtree(cls.dir, ignore_errors=True)

    def send_gigabyte(self, headers, chunked):
        """Sends a POST with these headers and up to 1 GiB of body (chunked or not) while
        reading the answer; returns its status line and the bytes sent before the server
        closed the connection."""
        sock = socket.create_connection(("127.0.0.1", self.studio.port), timeout=60)
        head = (f"POST /api/what-if HTTP/1.1\r\nHost: 127.0.0.1:{self.studio.port}\r\n"
                f"Content-Type: application/json\r\n{headers}\r\n").encode()
        sent = [0]

        def stream():
            block = b" " * MIB
            try:
                sock.sendall(head)
                for _ in range(1024):
                    sock.sendall(b"100000\r\n" + block + b"\r\n" if chunked else block)
                    sent[0] += MIB
                if chunked:
                    sock.sendall(b"0\r\n\r\n")
            except OSError:
                pass  # the server closed the connection: what it should do

        sender = threading.Thread(target=stream, daemon=True)
        sender.start()
        answer = b""
        while b"\r\n" not in answer:
            data = sock.recv(4096)
            if not data:
                break
            answer += data
        sender.join(timeout=120)
        sock.close()
        return answer.split(b"\r\n")[0].decode(), sent[0]

    def check(self, headers, chunked, status):
        before = peak_kib(self.studio.server_pid)
        line, sent = self.send_gigabyte(headers, chunked)
        grown = (peak_kib(self.studio.server_pid) - before) / 1024
        self.assertIn(f" {status} ", line)
        self.assertLess(grown, 20, f"the server's peak memory grew by {grown:.1f} MB ({sent / MIB:.0f} MiB sent)")
        self.assertEqual(self.studio.request("GET", "/api/state")[0], 200)  # and it goes on serving

    def test_a_chunked_gigabyte_is_refused_and_never_held(self):
        self.check("Transfer-Encoding: chunked\r\n", True, 411)

    def test_a_gigabyte_announced_by_its_length_is_refused(self):
        self.check(f"Content-Length: {1024 * MIB}\r\n", False, 413)

    def test_a_body_without_a_length_is_stopped_at_the_limit(self):
        # What a server that passed such a body on would give the application: it reads no
        # more than the limit and answers 413.
        study = study_module.Study(quick_bench(), os.path.join(self.dir, "asgi"), start=False)
        app = studio_app.create_app(study, port=8035)
        pulled = [0]
        answer = {}

        async def receive():
            await asyncio.sleep(0)  # as a server's would, it waits for the network
            if "status" in answer or pulled[0] == 16384:
                return {"type": "http.disconnect"}
            pulled[0] += 1
            return {"type": "http.request", "body": b" " * 65536, "more_body": pulled[0] < 16384}

        async def send(message):
            if message["type"] == "http.response.start":
                answer["status"], answer["pulled"] = message["status"], pulled[0]

        scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": "POST",
                 "scheme": "http", "path": "/api/what-if", "raw_path": b"/api/what-if", "query_string": b"",
                 "root_path": "", "client": ("127.0.0.1", 50000), "server": ("127.0.0.1", 8035),
                 "headers": [(b"host", b"127.0.0.1:8035"), (b"content-type", b"application/json")]}
        try:
            asyncio.run(app(scope, receive, send))
        finally:
            study.close()
        self.assertEqual(answer["status"], 413)
        self.assertLessEqual(answer["pulled"], 2)  # at most 128 KiB taken of the 1 GiB offered, then the answer

    def test_json_nested_deep_answers_422(self):
        body = b"[" * 7000 + b"]" * 7000
        status, data = self.studio.request("POST", "/api/what-if", body, {"Content-Type": "application/json"})
        self.assertEqual(status, 422, data)
        self.assertIn("nests too deep", json.loads(data)["errors"]["form"])


class ExposedModeTest(unittest.TestCase):
    """With --host: every request carries the token (query, then cookie) and names this server
    in Host (a loopback name, --host's, an --allow-host one, or an address)."""

    PORT = 8035

    @classmethod
    def setUpClass(cls):
        from fastapi.testclient import TestClient
        cls.dir = tempfile.mkdtemp(prefix="fretbuzz-studio-test-")
        cls.study = study_module.Study(quick_bench(), os.path.join(cls.dir, "study"), start=False)
        cls.app = studio_app.create_app(cls.study, port=cls.PORT, host="0.0.0.0", allow_hosts=["studio.lan"])
        cls.token = cls.app.state.token
        cls.TestClient = TestClient

    @classmethod
    def tearDownClass(cls):
        cls.study.close()
        shutil.rmtree(cls.dir, ignore_errors=True)

    def client(self, address="192.0.2.7"):
        return self.TestClient(client_at(self.app, address), base_url=f"http://127.0.0.1:{self.PORT}")

    def test_every_request_needs_the_token(self):
        self.assertGreaterEqual(len(self.token), 32)
        for address in ("192.0.2.7", "127.0.0.1"):
            client = self.client(address)
            for path in ("/", "/api/state", "/static/studio.js", "/fragment/maps", "/study/maps/001/x.wav",
                         "/?token=", "/?token=" + self.token[:-1] + ("x" if self.token[-1] != "x" else "y")):
                self.assertEqual(client.get(path).status_code, 401, (address, path))
            self.assertEqual(client.post("/api/what-if", json={"strengths": "medium"}).status_code, 401)

    def test_the_token_in_the_address_becomes_a_cookie(self):
        client = self.client()
        page = client.get(f"/?token={self.token}")
        self.assertEqual(page.status_code, 200)
        cookie = page.headers["set-cookie"]
        self.assertIn(f"fretbuzz_studio_{self.PORT}={self.token}", cookie)
        self.assertIn("HttpOnly", cookie)
        self.assertIn("SameSite=strict", cookie)
        self.assertEqual(client.get("/api/state").status_code, 200)  # the cookie, kept by the client
        self.assertEqual(client.post("/api/what-if", json={"strengths": "medium"}).status_code, 202)

    def test_a_rebinding_host_is_refused_even_with_the_token(self):
        client = self.client()
        for host in (f"evil.example:{self.PORT}", f"studio.lan.evil.example:{self.PORT}", f"studio.lan:{self.PORT + 1}"):
            response = client.get(f"/api/state?token={self.token}", headers={"Host": host})
            self.assertEqual(response.status_code, 400, host)
            self.assertIn("--allow-host", response.json()["error"])
        for host in (f"studio.lan:{self.PORT}", f"192.168.1.20:{self.PORT}", f"[fd00::5]:{self.PORT}",
                     f"localhost:{self.PORT}"):
            self.assertEqual(client.get(f"/api/state?token={self.token}", headers={"Host": host}).status_code, 200, host)
        refused = client.post(f"/api/what-if?token={self.token}", json={"strengths": "medium"},
                              headers={"Origin": "http://evil.example"})
        self.assertEqual(refused.status_code, 403)

    def test_the_command_prints_the_token_and_warns(self):
        studio = ServedStudio("--study", os.path.join(self.dir, "served"), "--host", "127.0.0.1",
                              "--allow-host", "studio.lan")
        try:
            self.assertIsNotNone(studio.token, studio.line)
            self.assertEqual(studio.request("GET", "/api/state")[0], 401)
            self.assertEqual(studio.request("GET", f"/api/state?token={studio.token}")[0], 200)
            self.assertEqual(studio.request("GET", f"/api/state?token={studio.token}",
                                            headers={"Host": f"evil.example:{studio.port}"})[0], 400)
        finally:
            code, err = studio.stop()
        self.assertEqual(code, 0, err)
        self.assertIn("warning: shared on the network: 127.0.0.1", err)
        self.assertIn(os.path.realpath(os.path.join(self.dir, "served")), err)
        self.assertIn("studio.lan", err)
        run = subprocess.run([sys.executable, "-m", "fretbuzz.studio", "--allow-host", "x"], capture_output=True,
                             text=True, timeout=60)
        self.assertEqual(run.returncode, 2)
        self.assertIn("--allow-host: give --host too", run.stderr)


class OneStudioPerFolderTest(unittest.TestCase):
    """A study folder has one studio; its maps appear whole or not at all; old ones go on request."""

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="fretbuzz-studio-test-")
        self.folder = os.path.join(self.dir, "study")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def test_a_second_study_on_the_folder_is_refused_naming_the_first(self):
        first = study_module.Study(quick_bench(), self.folder, start=False)
        with self.assertRaises(study_module.StudyBusy) as e:
            study_module.Study(quick_bench(), self.folder, start=False)
        self.assertIn(f"process {os.getpid()}", str(e.exception))
        first.close()
        study_module.Study(quick_bench(), self.folder, start=False).close()

    def test_a_second_studio_exits_1_naming_the_first_ones_process(self):
        first = ServedStudio("--study", self.folder)
        try:
            command = [CLI, "studio"] if CLI else [sys.executable, "-m", "fretbuzz.studio"]
            run = subprocess.run(command + ["bass-neck", "--port", "0", "--study", self.folder], capture_output=True,
                                 text=True, timeout=60)
            self.assertEqual(run.returncode, 1, run.stderr)
            self.assertIn(f"another studio works in {os.path.realpath(self.folder)} (process {first.server_pid})",
                          run.stderr)
            first.first_map_done()
            # Each map of the first studio is its own: numbered on, whole.
            self.assertEqual(sorted(os.listdir(os.path.join(self.folder, "maps"))), ["001"])
        finally:
            first.stop()

    def test_a_map_is_visible_only_when_whole(self):
        studio = RunningStudio(start=False)
        try:
            study = studio.study
            maps = os.path.join(study.folder, "maps")
            record = study.maps[1]
            study.start()
            wait_for(lambda: len(record.notes) >= 1, 60, "the first note")
            with study.lock:  # the worker waits here with the map's first note
                self.assertEqual(record.status, "running")
                self.assertEqual(os.listdir(maps), ["001" + study_module.PARTIAL])
                name = record.notes[0]["audio"]
                # The page already plays it, under the map's own address.
                self.assertEqual(study.path(f"maps/001/{name}"), os.path.join(maps, "001" + study_module.PARTIAL, name))
            studio.wait_map(1)
            self.assertEqual(os.listdir(maps), ["001"])
            self.assertEqual(sorted(os.listdir(os.path.join(maps, "001"))),
                             sorted(n["audio"] for n in record.notes if n["audio"]))
            self.assertEqual(studio.request("GET", f"/study/maps/001/{name}")[0], 200)
        finally:
            studio.close()

    def test_a_map_left_unfinished_by_a_kill_is_removed_by_the_next_studio(self):
        first = ServedStudio("--study", self.folder, "--strength", "soft,medium,hard,pop,slap")
        partial = os.path.join(self.folder, "maps", "001" + study_module.PARTIAL)
        wait_for(lambda: os.path.isdir(partial) and os.listdir(partial), 60, "the first WAVs")
        first.process.kill()
        first.process.communicate(timeout=30)
        self.assertEqual(os.listdir(os.path.join(self.folder, "maps")), ["001" + study_module.PARTIAL])
        second = ServedStudio("--study", self.folder)  # its first map: medium only
        try:
            second.first_map_done()
            self.assertEqual(os.listdir(os.path.join(self.folder, "maps")), ["001"])
            wavs = os.listdir(os.path.join(self.folder, "maps", "001"))
            self.assertEqual(len(wavs), 21)
            self.assertTrue(all(name.endswith("-medium.wav") for name in wavs), wavs)
        finally:
            code, err = second.stop()
        self.assertIn("removed 1 unfinished and 0 old map(s)", second.line + err)

    def make_maps(self, whole=4):
        """A study folder as a killed studio leaves it: `whole` maps, an unfinished one, a report."""
        study_module.Study(quick_bench(), self.folder, start=False).close()
        for n in range(1, whole + 1):
            os.makedirs(os.path.join(self.folder, "maps", f"{n:03d}"))
        os.makedirs(os.path.join(self.folder, "maps", f"{whole + 1:03d}{study_module.PARTIAL}"))
        os.makedirs(os.path.join(self.folder, "exports"))
        open(os.path.join(self.folder, "exports", "report-001.html"), "w").close()

    @unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
    def test_fretbuzz_clean_prunes_old_maps_on_request(self):
        self.make_maps()
        listing = lambda: sorted(os.listdir(os.path.join(self.folder, "maps")))  # noqa: E731
        run = subprocess.run([CLI, "clean", self.folder], capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertEqual(listing(), ["001", "002", "003", "004"])
        run = subprocess.run([CLI, "clean", self.folder, "--keep-maps", "2"], capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertIn("removed 0 unfinished maps and 2 old maps", run.stderr)
        self.assertEqual(listing(), ["003", "004"])
        self.assertTrue(os.path.exists(os.path.join(self.folder, "exports", "report-001.html")))
        # Not while a studio works in the folder.
        study = study_module.Study(quick_bench(), self.folder, start=False)
        try:
            run = subprocess.run([CLI, "clean", self.folder, "--keep-maps", "0"], capture_output=True, text=True,
                                 timeout=60)
            self.assertEqual(run.returncode, 1, run.stderr)
            self.assertIn(f"process {os.getpid()}", run.stderr)
            self.assertEqual(listing(), ["003", "004"])
        finally:
            study.close()
        run = subprocess.run([CLI, "clean", self.dir, "--keep-maps", "1"], capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 2, run.stderr)
        self.assertIn("not a study folder", run.stderr)

    def test_the_studio_prunes_old_maps_on_request(self):
        self.make_maps()
        studio = ServedStudio("--study", self.folder, "--keep-maps", "1")
        try:
            self.assertIn("removed 1 unfinished and 3 old map(s)", studio.line)
            studio.first_map_done()  # numbered on from the maps kept
            self.assertEqual(sorted(os.listdir(os.path.join(self.folder, "maps"))), ["004", "005"])
        finally:
            studio.stop()


@unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
class ServerLifetimeTest(unittest.TestCase):
    """`fretbuzz studio` runs the server as its child: the child ends with it, however it ends,
    and the script it was started with is gone once read."""

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="fretbuzz-studio-test-")
        self.scripts = os.path.join(self.dir, "tmp")
        os.makedirs(self.scripts)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def start(self):
        return ServedStudio("--study", os.path.join(self.dir, "study"), cli=True,
                            env={**os.environ, "TMPDIR": self.scripts})

    def test_the_script_is_removed_once_loaded(self):
        studio = self.start()
        try:
            self.assertEqual(os.listdir(self.scripts), [])
        finally:
            code, err = studio.stop()
        self.assertEqual(code, 0, err)

    def test_the_server_dies_with_the_command(self):
        studio = self.start()
        try:
            self.assertEqual(studio.request("GET", "/api/state")[0], 200)
            studio.process.send_signal(signal.SIGKILL)  # the command alone, not its group
            studio.process.communicate(timeout=30)
            wait_for(lambda: not alive(studio.server_pid), 30, "the server to end with the command")
            with self.assertRaises(OSError):
                studio.request("GET", "/api/state")
            # Its lock went with it: a new studio takes the folder.
            self.start().stop()
        finally:
            if alive(studio.server_pid):
                os.kill(studio.server_pid, signal.SIGKILL)


class CtrlCOnAThreadTest(unittest.TestCase):
    """Ctrl-C while Bench.map() runs on a thread other than the main one: the program ends as
    Ctrl-C ends it (KeyboardInterrupt, killed by SIGINT: exit 130 in a shell), never by abort."""

    SCRIPT = """
import sys, threading, fretbuzz
bench = fretbuzz.Bench("bass-neck", ensemble=2, fs=3e5, duration=0.05)
daemon = sys.argv[1] == "daemon"
def work():
    for _ in range(50 if daemon else 1):
        bench.map(strengths="soft,medium,hard,pop,slap")
thread = threading.Thread(target=work, daemon=daemon)
thread.start()
print("mapping", flush=True)
# Timed joins: a SIGINT whose handler runs just before an untimed join starts its lock wait
# leaves that wait uninterrupted until the thread ends (CPython's race, seen as a hang here:
# the main thread still in join, the map working on); a Ctrl-C program waits so.
while thread.is_alive():
    thread.join(0.1)
"""

    def interrupt(self, kind, delay):
        process = subprocess.Popen([sys.executable, "-c", self.SCRIPT, kind], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True)
        self.assertEqual(process.stdout.readline().strip(), "mapping")
        time.sleep(delay)
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=120)
        return process.returncode, err

    def test_ctrl_c_on_a_daemon_thread_twenty_times(self):
        rng = random.Random(50)
        for trial in range(20):
            code, err = self.interrupt("daemon", rng.uniform(0.0, 0.6))
            self.assertNotIn("terminate called", err, trial)
            self.assertEqual(code, -signal.SIGINT, f"trial {trial}: {err}")
            self.assertIn("KeyboardInterrupt", err)

    def test_ctrl_c_while_a_thread_maps_ends_after_its_map(self):
        code, err = self.interrupt("thread", 0.3)
        self.assertNotIn("terminate called", err)
        self.assertEqual(code, -signal.SIGINT, err)


class PythonArgumentsTest(unittest.TestCase):
    """Each bad argument is named with its range and the value given; a bool is not a number."""

    @classmethod
    def setUpClass(cls):
        cls.bench = fretbuzz.Bench("bass-neck")

    def test_numbers_of_the_wrong_kind_name_the_field_and_its_range(self):
        for value in (1.5, True, "3"):
            with self.assertRaises(TypeError, msg=repr(value)) as e:
                fretbuzz.Bench("bass-neck", ensemble=value)
            self.assertIn("ensemble", str(e.exception))
            self.assertIn("[1, 200]", str(e.exception))
            self.assertIn(repr(value), str(e.exception))
        for value in (0, 201, 10 ** 30):
            with self.assertRaises(fretbuzz.InputError) as e:
                fretbuzz.Bench("bass-neck", ensemble=value)
            self.assertIn(f"ensemble (the most plucks per note) = {value} is out of range", str(e.exception))
        with self.assertRaises(TypeError) as e:
            fretbuzz.Bench("bass-neck", fs=True)
        self.assertIn("fs (Hz, in [50000, 2e7])", str(e.exception))
        with self.assertRaises(fretbuzz.InputError):
            self.bench.map(frets=True)

    def test_fret_offsets_keys_are_frets(self):
        with self.assertRaises(TypeError) as e:
            self.bench.with_changes(fret_offsets={"3": 0.1})
        self.assertIn("fret_offsets", str(e.exception))
        self.assertIn("'3'", str(e.exception))
        with self.assertRaises(fretbuzz.InputError) as e:
            self.bench.with_changes(fret_offsets={21: 0.1})
        self.assertIn("frets 1 to 20", str(e.exception))
        with self.assertRaises(fretbuzz.InputError) as e:
            self.bench.with_changes(fret_offsets={-1: 0.1})
        self.assertIn("fret_offsets", str(e.exception))

    def test_a_relief_of_zero_is_a_change(self):
        flat = self.bench.with_changes(relief=0)
        self.assertEqual(flat.changes, {"relief": 0})
        self.assertAlmostEqual(flat.strings_table()["relief_gap_m"][0], 0.0, delta=1e-9)
        self.assertEqual(self.bench.with_changes(action12={}).changes, {})

    def test_rows_of_a_map_name_their_field(self):
        row = {"string": "G", "fret": "3", "strength": "medium", "buzz_fraction": 0.0, "buzz_dB": None,
               "buzz_fret": None}
        with self.assertRaises(TypeError) as e:
            fretbuzz.Bench.compare([row], [])
        self.assertIn("map row 0: fret", str(e.exception))
        with self.assertRaises(fretbuzz.InputError) as e:
            fretbuzz.Bench.compare([{**row, "fret": 3, "buzz_fraction": 2.0}], [])
        self.assertIn("map row 0: buzz_fraction = 2", str(e.exception))

    def test_a_file_and_a_what_if_take_the_same_values(self):
        for text, change in (("1e-320 mm", {"action12": {"G": "1e-320 mm"}}), ("0.001 mm", {"nut": {"G": "0.001 mm"}})):
            with self.assertRaises(fretbuzz.InputError) as e:
                self.bench.with_changes(**change)
            self.assertIn("[0.01,", str(e.exception))
        with self.assertRaises(fretbuzz.InputError) as e:
            fretbuzz.Bench.from_text(bass_neck_text().replace('action = "2.34 mm"', 'action = "1e-320 mm"'))
        self.assertIn('string[0].action = "1e-320 mm" is out of range: must be in [0.01, 10] mm', str(e.exception))
        at_least = fretbuzz.Bench.from_text(bass_neck_text().replace('action = "2.34 mm"', 'action = "0.01 mm"'))
        self.assertEqual(at_least.instrument.name, "bass-neck")


class AsciiDigitsTest(unittest.TestCase):
    """Digits are ASCII digits: "٣" (Arabic-Indic three) is not 3."""

    def test_a_fret_in_other_digits_is_refused(self):
        studio = RunningStudio(start=False)
        try:
            status, body = studio.json("POST", "/api/what-if", {"fret": "٣", "fret_offset": "0.1", "strengths": "medium"})
            self.assertEqual(status, 422, body)
            self.assertIn("is not a fret", body["errors"]["fret"])
        finally:
            studio.close()
        self.assertEqual(studio_app.host_name("127.0.0.1:٨٠٣٥"), ("127.0.0.1", -1))

    def test_options_in_other_digits_are_refused(self):
        with tempfile.TemporaryDirectory() as d:
            for option in (["--port", "٨٠٣٥"], ["--ensemble", "٣"], ["--fs", "٣e5"], ["--jobs", "٢"]):
                run = subprocess.run([sys.executable, "-m", "fretbuzz.studio", "bass-neck", "--port", "0", *option],
                                     capture_output=True, text=True, timeout=60, cwd=d)
                self.assertEqual(run.returncode, 2, option)
                self.assertIn(option[0], run.stderr)
                self.assertEqual(os.listdir(d), [])


class ExportOnAFullDiskTest(unittest.TestCase):
    """A full disk during an export: a JSON 507 that says so, and no temporary file left."""

    def export_refused(self, studio):
        status, body = studio.json("POST", "/api/export", {"map": 1})
        self.assertEqual(status, 507, body)
        self.assertIn("disk of the study folder is full", body["error"])
        exports = os.path.join(studio.study.folder, "exports")
        self.assertEqual(os.listdir(exports) if os.path.isdir(exports) else [], [])

    def test_a_full_disk_by_fault_injection(self):
        studio = RunningStudio()
        written = []

        def full(fd, data):  # the disk takes 1000 bytes, then is full
            if sum(written) >= 1000:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            written.append(os.write(fd, bytes(data[:1000])))
            return written[-1]

        try:
            studio.wait_map(1)
            studio_app.write_bytes = full
            self.export_refused(studio)
            self.assertEqual(sum(written), 1000)
            studio_app.write_bytes = os.write
            self.assertEqual(studio.json("POST", "/api/export", {"map": 1})[0], 200)
        finally:
            studio_app.write_bytes = os.write
            studio.close()

    @unittest.skipUnless(hasattr(os, "geteuid") and os.geteuid() == 0, "mounting a small file system needs root")
    def test_a_full_disk_on_a_small_file_system(self):
        mount = tempfile.mkdtemp(prefix="fretbuzz-full-disk-")  # 16 MB: room for one map of 1.5 s notes
        if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16m", "tmpfs", mount], capture_output=True).returncode:
            os.rmdir(mount)
            self.skipTest("mount -t tmpfs is not allowed here")
        try:
            studio = RunningStudio(dir=mount)
            try:
                studio.wait_map(1)
                with open(os.path.join(mount, "filler"), "wb", buffering=0) as f:
                    with self.assertRaises(OSError) as full:
                        while True:
                            f.write(b"\0" * 4096)
                self.assertEqual(full.exception.errno, errno.ENOSPC)
                self.export_refused(studio)
                os.unlink(os.path.join(mount, "filler"))
                self.assertEqual(studio.json("POST", "/api/export", {"map": 1})[0], 200)
            finally:
                studio.close()
        finally:
            subprocess.run(["umount", "-l", mount])
            os.rmdir(mount)

if __name__ == "__main__":
    unittest.main()
