// `fretbuzz sweep SPEC.toml`: run a case over lists or grids of case-file values, on the
// threads of this machine or (--scheduler) on a Dask cluster through the Python driver,
// into one table of parameters and buzz metrics.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <unistd.h>

#include "../Commands.hpp"
#include "../PythonScript.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/sweep/Sweep.hpp"

namespace fretbuzz::cli {

namespace {

struct SweepArguments {
    std::string spec;
    std::string out;
    unsigned jobs = 0;
    bool resume = false;
    std::string scheduler;
    double scheduler_timeout = 10.0;
    std::size_t max_runs = kDefaultMaxSweepRuns;
    bool quiet = false;
};

std::string clock_text(double seconds) {
    char text[32];
    const long s = static_cast<long>(seconds + 0.5);
    std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
    return text;
}

// The Dask driver lives in the Python package (fretbuzz.sweeps, the same compiled library
// on every worker).
int dask_sweep(const SweepArguments& a) {
    std::vector<std::string> args{a.spec, "--out", a.out, "--scheduler", a.scheduler, "--timeout",
                                  std::to_string(a.scheduler_timeout)};
    if (a.resume) args.push_back("--resume");
    if (a.quiet) args.push_back("--quiet");
    args.insert(args.end(), {"--max-runs", std::to_string(a.max_runs)});
    return run_package_main("sweeps", args);
}

// A line about every half second while the runs' cases are checked (a large grid takes
// a while): how many of how many.
SweepCheckProgress checking_progress(bool terminal) {
    auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
    auto shown = std::make_shared<bool>(false);
    return [terminal, last, shown](std::size_t checked, std::size_t total) {
        const auto now = std::chrono::steady_clock::now();
        if (checked < total && now - *last < std::chrono::milliseconds(500)) return;
        if (checked == total && !*shown) return;  // quick: nothing to say
        *last = now;
        *shown = true;
        std::cerr << (terminal ? "\r" : "") << "fretbuzz: checking the runs' cases: " << checked << "/" << total
                  << (terminal && checked < total ? "   " : "\n") << std::flush;
    };
}

std::string resume_hint(const SweepArguments& a) {
    return "finish it with: fretbuzz sweep " + a.spec + " --out " + a.out + " --resume";
}

int sweep_command(const SweepArguments& a) {
    if (!a.scheduler.empty()) {
        if (!(a.scheduler_timeout > 0.0 && a.scheduler_timeout <= 3600.0))
            throw InputError(out_of_range_message("--scheduler-timeout", a.scheduler_timeout, "must be in (0, 3600] s"));
        if (a.jobs != 0) throw InputError("--jobs: with --scheduler the cluster's workers set the parallelism");
        return dask_sweep(a);
    }
    stop_cleanly_on_signals();  // Ctrl-C: the finished rows are kept, and said so
    const SweepSpec spec = load_sweep(a.spec, a.max_runs);
    SweepOptions options;
    options.jobs = a.jobs;
    options.resume = a.resume;
    const bool terminal = ::isatty(STDERR_FILENO) != 0;
    if (!a.quiet) options.checking = checking_progress(terminal);
    if (!a.quiet)
        options.progress = [terminal](const SweepProgress& p) {
            std::cerr << (terminal ? "\r" : "") << "fretbuzz: sweep " << p.done << "/" << p.total << " runs";
            if (p.failed) std::cerr << ", " << p.failed << " failed";
            std::cerr << ", elapsed " << clock_text(p.elapsed_s) << ", ETA " << clock_text(p.remaining_s)
                      << (terminal ? "   " : "\n") << std::flush;
        };
    const SweepOutcome outcome = run_sweep(spec, a.out, options);
    if (!a.quiet && outcome.computed > 0 && terminal) std::cerr << "\n";
    if (outcome.interrupted) {
        std::cerr << "\nfretbuzz: interrupted after " << outcome.computed << " runs in " << outcome.wall_seconds
                  << " s; the " << outcome.resumed + outcome.computed << " finished runs of " << outcome.total
                  << " are kept in " << a.out << "/runs; " << resume_hint(a) << "\n";
        return 128 + (outcome.signal != 0 ? outcome.signal : 2);
    }
    std::cerr << "fretbuzz: " << outcome.total << " runs (" << outcome.computed << " computed";
    if (outcome.resumed) std::cerr << ", " << outcome.resumed << " from before";
    std::cerr << ", " << outcome.failed << " failed) on " << outcome.jobs << " threads in " << outcome.wall_seconds
              << " s; table in " << a.out << "/results.csv and results.h5\n";
    return 0;
}

}  // namespace

void add_sweep_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<SweepArguments>();
    CLI::App* cmd = app.add_subcommand(
        "sweep", "Run a case over lists or grids of case-file values; one table of parameters and buzz metrics");
    cmd->add_option("spec", args->spec, "Sweep spec (.toml): [sweep] case = ..., [[parameter]] key = ..., values = [...]")
        ->required();
    cmd->add_option("--out", args->out, "Output directory (rows in runs/, the table in results.csv and results.h5)")
        ->required();
    cmd->add_option("--jobs", args->jobs, "Runs at a time on this machine (default: the hardware's threads)");
    cmd->add_flag("--resume", args->resume, "Finish an interrupted sweep in --out: run only the missing rows");
    cmd->add_option("--scheduler", args->scheduler, "Run on a Dask cluster: the scheduler's address, tcp://HOST:PORT");
    cmd->add_option("--scheduler-timeout", args->scheduler_timeout,
                    "Seconds to wait for the scheduler to answer (default 10)");
    cmd->add_option("--max-runs", args->max_runs,
                    "Refuse a spec of more runs than this (default " + std::to_string(kDefaultMaxSweepRuns) +
                        "; at most " + std::to_string(kMostSweepRuns) + ")");
    cmd->add_flag("--quiet", args->quiet, "No progress lines");
    cmd->callback([args, &action] { action = [args] { return sweep_command(*args); }; });
}

}  // namespace fretbuzz::cli
