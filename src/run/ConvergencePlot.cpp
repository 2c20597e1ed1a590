// The log-log plot of a convergence study. The script lives here as text so the installed
// binary can draw without the source tree; it is written to a temporary file and run.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "fretbuzz/run/ConvergenceOutput.hpp"

namespace fretbuzz {

namespace {

constexpr const char* kPlotScript = R"PY(
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

csv_path, png_path, title, threshold, name = sys.argv[1:6]
threshold = float(threshold)
rows = list(csv.DictReader(open(csv_path)))
values = [float(r["value"]) for r in rows]
errors = [float(r["relative_error"]) for r in rows]
fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=100)
ax.loglog(values, errors, "o-", label="relative L2 error")
ax.axhline(threshold, color="tab:red", ls="--", lw=1, label=f"threshold {threshold:g}")
for v, e, r in zip(values, errors, rows):
    if r["observed_order"]:
        ax.annotate(f"{float(r['observed_order']):.2f}", (v, e), textcoords="offset points", xytext=(4, 6), fontsize=8)
ax.set_xlabel("fs [Hz]" if name == "fs" else "K")
ax.set_ylabel("relative L2 error")
ax.set_title(title, fontsize=9)
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(png_path)
)PY";

// Runs argv without a shell (no quoting problems with paths); returns the exit status.
int run_program(const std::vector<std::string>& argv) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const pid_t child = ::fork();
    if (child < 0) return -1;
    if (child == 0) {
        ::execv(args[0], args.data());
        ::_exit(127);
    }
    int status = 0;
    if (::waitpid(child, &status, 0) < 0) return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

PlotOutcome plot_convergence(const ConvergenceReport& r, const std::filesystem::path& csv,
                             const std::filesystem::path& png, const std::string& python) {
    PlotOutcome outcome;
    if (!std::filesystem::exists(python)) {
        outcome.message = python + " not found; no plot drawn";
        return outcome;
    }
    const std::filesystem::path script = png.parent_path() / ".plot_convergence.py";
    {
        std::ofstream out(script);
        out << kPlotScript;
        if (!out) {
            outcome.message = "cannot write the plot script to " + script.string();
            return outcome;
        }
    }
    std::ostringstream title, threshold;
    title << r.case_name << ": error against the reference " << parameter_name(r.parameter) << " = " << r.reference
          << ", window " << r.window_s << " s";
    threshold << r.threshold;
    const int status = run_program({python, script.string(), csv.string(), png.string(), title.str(), threshold.str(),
                                    parameter_name(r.parameter)});
    std::filesystem::remove(script);
    outcome.written = status == 0 && std::filesystem::exists(png);
    if (!outcome.written)
        outcome.message = python + " could not draw the plot (is matplotlib installed?); the CSV is complete";
    return outcome;
}

}  // namespace fretbuzz
