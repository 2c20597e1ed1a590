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
#include <string>

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
        // --help and --version end the parse with status 0; any other parse error is bad input.
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
