// The fretbuzz command: a thin layer that parses arguments and calls the library.
// Exit status: 0 success, 2 bad input (command line or case), 1 an I/O failure (a full
// disk, an unreadable output), 3 a numerical failure, 128 + the signal when interrupted.
#include <csignal>
#include <iostream>
#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#endif
#include <algorithm>
#include <charconv>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "Commands.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/Version.hpp"

namespace fretbuzz::cli {

namespace {
extern "C" void on_stop_signal(int signal) { request_stop(signal); }
}  // namespace

void stop_cleanly_on_signals() {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    for (int signal : {SIGINT, SIGTERM}) sigaction(signal, &action, nullptr);
}

namespace {
std::string invocation;

// A run streams its outputs through buffers that zlib (inside HDF5) allocates and frees for
// every chunk it compresses. By default glibc hands such memory back to the kernel at each
// free (above 128 KiB at the heap's top) and the next chunk faults it in again, page by page:
// thousands of faults per simulated second at audio rates. Keeping it costs a few MiB.
void keep_freed_memory() {
#if defined(__GLIBC__)
    mallopt(M_TRIM_THRESHOLD, 128 << 20);
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    // The heap grows once by 64 MiB of address space, offered to the kernel for huge pages:
    // a run's first few MiB (HDF5's caches, the case, the buffers) then cost a few faults
    // of 2 MiB instead of about a thousand of 4 KiB, each of which costs microseconds.
    // Only untouched address space is reserved; memory is taken as it is used.
    mallopt(M_TOP_PAD, 64 << 20);
    void* probe = malloc(std::size_t{1} << 20);  // more than the heap has left: it grows now
    if (probe != nullptr) {
        constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
        const auto from = (reinterpret_cast<std::uintptr_t>(probe) + kHuge - 1) & ~(kHuge - 1);
        const auto to = reinterpret_cast<std::uintptr_t>(sbrk(0));
        if (to > from) (void)madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);  // only a hint
        free(probe);
    }
#endif
}

// Edits (insertions, deletions, substitutions, swaps of neighbours) from a to b.
std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i)
        for (std::size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

// The registered name nearest to `word`, if near enough to be what was meant (at most a
// third of its letters wrong, and at least one right).
std::optional<std::string> nearest(std::string_view word, const std::vector<std::string>& names) {
    std::optional<std::string> best;
    std::size_t best_distance = std::max<std::size_t>(1, word.size() / 3) + 1;
    for (const std::string& name : names)
        if (const std::size_t d = edit_distance(word, name); d < best_distance) {
            best_distance = d;
            best = name;
        }
    return best;
}

std::vector<std::string> option_names(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::Option* option : app.get_options()) {
        for (const std::string& l : option->get_lnames()) names.push_back("--" + l);
        for (const std::string& s : option->get_snames()) names.push_back("-" + s);
    }
    return names;
}

bool is_number(std::string_view word) {
    double value = 0.0;
    const auto r = std::from_chars(word.data(), word.data() + word.size(), value);
    return r.ec == std::errc() && r.ptr == word.data() + word.size();
}

// After a parse error: "did you mean" for a misspelt subcommand or option of the command
// line, or nothing when every word is known.
std::optional<std::string> suggestion(CLI::App& app, int argc, char** argv) {
    std::vector<std::string> commands;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) commands.push_back(sub->get_name());
    CLI::App* command = &app;
    for (int k = 1; k < argc; ++k) {
        const std::string_view word = argv[k];
        if (word == "--") break;
        if (word.starts_with("-") && !is_number(word)) {
            const std::string name(word.substr(0, word.find('=')));
            const std::vector<std::string> known = option_names(*command);
            if (std::find(known.begin(), known.end(), name) != known.end()) continue;
            if (const auto near = nearest(name, known))
                return "unknown option " + name + (command == &app ? "" : " of `fretbuzz " + command->get_name() + "`") +
                       "; did you mean " + *near + "?";
            continue;
        }
        if (command != &app) continue;  // a value or a positional of the subcommand
        if (std::find(commands.begin(), commands.end(), word) != commands.end()) {
            command = app.get_subcommand(std::string(word));
            continue;
        }
        if (const auto near = nearest(word, commands))
            return "unknown command '" + std::string(word) + "'; did you mean `fretbuzz " + *near + "`?";
        return "unknown command '" + std::string(word) + "' (fretbuzz --help lists the commands)";
    }
    return std::nullopt;
}

}  // namespace
const std::string& command_line() { return invocation; }
}  // namespace fretbuzz::cli

int main(int argc, char** argv) {
    using namespace fretbuzz;
    cli::keep_freed_memory();
    for (int k = 0; k < argc; ++k) cli::invocation.append(k > 0 ? " " : "").append(argv[k]);
    CLI::App app{"fretbuzz: strings vibrating against obstacles (modal scheme, exact energy balance)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "fretbuzz " + std::string(version));
    cli::Action action;
    cli::add_run_command(app, action);
    cli::add_cases_commands(app, action);
    cli::add_convergence_command(app, action);
    cli::add_cross_check_command(app, action);
    cli::add_modes_command(app, action);
    cli::add_plot_command(app, action);
    cli::add_report_command(app, action);
    cli::add_sweep_command(app, action);
    cli::add_setup_command(app, action);
    cli::add_studio_command(app, action);
    cli::add_estimate_command(app, action);
    cli::add_play_command(app, action);
    cli::add_clean_command(app, action);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version end the parse with status 0; any other parse error is bad input,
        // said with the nearest known name when a word of the command line is misspelt.
        if (e.get_exit_code() != 0)
            if (const auto hint = cli::suggestion(app, argc, argv)) {
                std::cerr << "fretbuzz: error: " << *hint << "\nRun with --help for more information.\n";
                return 2;
            }
        const int status = app.exit(e);
        return status == 0 ? 0 : 2;
    }
    try {
        return action ? action() : 0;
    } catch (const InputError& e) {
        std::cerr << "fretbuzz: error: " << e.what() << "\n";
        return 2;
    } catch (const Interrupted& e) {
        std::cerr << "\nfretbuzz: " << e.what() << "; no results written\n";
        return 128 + e.signal();
    } catch (const SolverError& e) {
        std::cerr << "fretbuzz: solver error: " << e.what() << "\n";
        return 3;
    } catch (const std::exception& e) {
        std::cerr << "fretbuzz: failed: " << e.what() << "\n";
        return 1;
    }
}
