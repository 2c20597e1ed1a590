// `fretbuzz run`: load a case, apply command-line overrides, simulate, write the outputs.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "../Commands.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/RunLength.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/output/RunOutputs.hpp"
#include "fretbuzz/output/StringsOutputs.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/run/StringsRun.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"

namespace fretbuzz::cli {

namespace {

struct RunArguments {
    std::string case_name;
    std::optional<double> fs, duration, stiffness, exponent, restitution;
    std::optional<std::string> law;
    bool lossless = false;
    bool allow_aliasing = false;
    std::vector<double> observe;
    std::optional<long> fret;
    std::optional<long> polarisations;
    std::optional<double> angle, pickup_angle;
    std::optional<std::string> output_rate;
    std::optional<double> audio_rate;
    bool velocity_audio = false;
    double snapshot_rate_hz = 0.0;
    std::optional<double> snapshot_until_s;
    bool report = false;
    std::string out = "fretbuzz-out";
    bool no_screen = false;
    bool no_free_flight = false;
    bool dense_contact_map = false;
    bool quiet = false;
    AudioFades fades;
    std::vector<std::string> one_string_only;  // given options that a strings case does not take
};

double parse_rate(const std::string& text) {
    try {
        std::size_t used = 0;
        const double value = std::stod(text, &used);
        if (used == text.size()) return value;
    } catch (const std::exception&) {
    }
    throw InputError("--output-rate " + text + ": must be a rate in Hz or 'native'");
}

void apply_overrides(const RunArguments& a, Case& c) {
    if (a.fs) c.run.sample_rate_hz = *a.fs;
    if (a.duration) set_duration(c, *a.duration);  // the finger and gesture profiles cut to the run
    if (a.stiffness) c.contact.stiffness = *a.stiffness;
    if (a.exponent) c.contact.exponent = *a.exponent;
    if (a.law) c.contact.law = contact_law_named(*a.law, "--law");
    if (a.restitution) {
        if (c.contact.law != ContactLawKind::impact)
            throw InputError("--restitution needs the impact law (--law impact, or contact.law = \"impact\")");
        if (!(*a.restitution >= 0.0 && *a.restitution <= 1.0))
            throw InputError(out_of_range_message("--restitution", *a.restitution, "must be in [0, 1]"));
        c.contact.restitution = *a.restitution;
    }
    if (a.audio_rate) c.run.audio_rate_hz = *a.audio_rate;
    if (a.lossless) c.make_lossless();
    if (a.allow_aliasing) c.run.allow_aliasing = true;
    c.observation_points_m.insert(c.observation_points_m.end(), a.observe.begin(), a.observe.end());
    // A case's default output rate above a lower --fs (say 48 kHz at --fs 44100) becomes fs.
    if (a.fs && !a.output_rate && c.run.output_rate_hz && *c.run.output_rate_hz > c.run.sample_rate_hz)
        c.run.output_rate_hz.reset();
    if (a.output_rate) {
        if (*a.output_rate == "native")
            c.run.output_rate_hz.reset();
        else
            c.run.output_rate_hz = parse_rate(*a.output_rate);
    }
    if (a.polarisations) {
        if (*a.polarisations != 1 && *a.polarisations != 2)
            throw InputError(out_of_range_message("--polarisations", static_cast<double>(*a.polarisations), "must be 1 or 2"));
        c.polarisation.count = static_cast<int>(*a.polarisations);
    }
    if (a.angle) c.polarisation.angle_deg = *a.angle;
    if (a.pickup_angle) {
        c.polarisation.pickup_angle_deg = *a.pickup_angle;
        c.polarisation.pickup_angle_given = true;
    }
    if (a.fret) {
        if (*a.fret < 1)
            throw InputError(out_of_range_message("--fret", static_cast<double>(*a.fret), "must be a fret number >= 1"));
        c.add_fret_finger(static_cast<std::size_t>(*a.fret), "--fret");
    }
}

void print_progress(const Progress& p) {
    std::fprintf(stderr, "\r  %5.1f%%  t = %.4f s  elapsed %.1f s  ETA %.1f s   ", 100.0 * p.fraction, p.simulated_s,
                 p.elapsed_s, p.remaining_s);
    std::fflush(stderr);
}

// A lower --fs than the case was written for (say 48 kHz) can put a mode so near a multiple
// of fs that contact aliases it onto a very low frequency, which would refuse the run: keep
// the modes below fs/2 instead, say so, and record it. A rate at which the modes above fs/2
// only warn keeps them all, as before; so does --allow-aliasing.
void keep_modes_in_band(const RunArguments& a, Case& c) {
    if (!a.fs || c.run.allow_aliasing || !contact_possible(c)) return;
    if (check_sampling(c.modes, c.run.sample_rate_hz).hazardous.empty()) return;
    const std::size_t given = c.mode_count();
    const std::size_t kept = modes_below_nyquist(c.modes, c.run.sample_rate_hz);
    if (kept == given || kept == 0) return;
    std::string how = "the case read again with string.modes = " + std::to_string(kept);
    try {
        Case in_band = with_mode_count(read_case_text(a.case_name), kept);
        apply_overrides(a, in_band);
        c = std::move(in_band);
    } catch (const InputError&) {
        // Data tied to the mode count (a modal excitation table): truncate the modal state,
        // the obstacle sampled on the coarser grid.
        c = stopped_string(c, 0.0, kept);
        how = "the first " + std::to_string(kept) + " modes of the case's initial state, the obstacle on their grid";
    }
    std::ostringstream why;
    why << "automatic: the " << kept << " modes at or below fs/2 = " << 0.5 * c.run.sample_rate_hz << " Hz of the case's "
        << given << ", " << how << " (--allow-aliasing keeps them all)";
    c.mode_choice = why.str();
    c.warnings.push_back("--fs " + std::to_string(std::lround(c.run.sample_rate_hz)) + ": string.modes = " +
                         std::to_string(kept) + ", the modes below fs/2 (the case has " + std::to_string(given) +
                         "; --allow-aliasing keeps them all, aliased under contact)");
}

// The options a strings case takes: its [run]'s (for the case and every string), and the
// outputs'. The others are each string's own business, set in its case (set.KEY).
void apply_strings_overrides(const RunArguments& a, StringsCase& sc) {
    if (!a.one_string_only.empty())
        throw InputError(a.one_string_only.front() + ": applies to one-string cases; " + a.case_name +
                         " is strings on a bridge (set it in a [[string]]'s case or its set table)");
    if (a.fs) {
        sc.run.sample_rate_hz = *a.fs;
        for (Case& c : sc.strings) c.run.sample_rate_hz = *a.fs;
    }
    if (a.duration) set_duration(sc, *a.duration);
    if (a.audio_rate) sc.run.audio_rate_hz = *a.audio_rate;
    if (a.output_rate) sc.run.output_rate_hz = *a.output_rate == "native" ? sc.run.sample_rate_hz : parse_rate(*a.output_rate);
    for (Case& c : sc.strings) {
        if (a.allow_aliasing) c.run.allow_aliasing = true;
        if (a.lossless) c.make_lossless();
    }
    if (a.lossless)  // as the case's run.lossless
        for (BridgeModeSpec& m : sc.bridge) m.damping_ratio = 0.0;
}

// Strings on a bridge: the whole assembly in one run, its rows and sound written as they come.
int run_strings_command(const RunArguments& a, const CaseText& text) {
    StringsCase sc = parse_strings_case(text);
    apply_strings_overrides(a, sc);
    sc.validate();  // after every override, before anything is created on disk
    for (const Case& c : sc.strings)
        if (contact_possible(c)) require_sampling(c.modes, c.run.sample_rate_hz, c.run.allow_aliasing);
    for (std::size_t s = 0; s < sc.strings.size(); ++s)
        for (const std::string& w : sc.strings[s].warnings)
            std::cerr << "fretbuzz: warning: string " << sc.string_names[s] << ": " << w << "\n";
    if (!a.quiet)
        std::cerr << "fretbuzz: " << sc.name << ": " << sc.strings.size() << " strings on a bridge of "
                  << sc.bridge.size() << " modes, fs = " << sc.run.sample_rate_hz << " Hz, " << sc.run.duration_s << " s\n";
    StringsOutputs outputs(a.out, sc);
    const StringsSummary run = simulate_strings(sc, outputs);
    outputs.commit(run);
    if (!a.quiet)
        std::cerr << "fretbuzz: " << run.steps << " steps in " << run.wall_seconds << " s ("
                  << run.wall_seconds / sc.run.duration_s << " s per simulated second); largest relative balance error "
                  << run.max_relative_balance_error << "; outputs in " << outputs.path().string() << "\n";
    if (a.report) return make_report(outputs.path(), a.quiet);
    if (!a.quiet) std::cerr << "fretbuzz: the strings' energies plotted and an HTML report: fretbuzz report " << outputs.path().string() << "\n";
    return 0;
}

int run_command(const RunArguments& a) {
    stop_cleanly_on_signals();
    if (const auto strings = read_strings_case_text(a.case_name)) return run_strings_command(a, *strings);
    Case c = load_case(a.case_name);
    apply_overrides(a, c);
    keep_modes_in_band(a, c);
    c.validate();  // before anything is created on disk
    // Refuses a sampling rate at which modes alias onto low frequencies (as planning does).
    const SamplingReport sampling =
        contact_possible(c) ? require_sampling(c.modes, c.run.sample_rate_hz, c.run.allow_aliasing) : SamplingReport{};
    std::vector<std::string> warnings = c.warnings;
    warnings.insert(warnings.end(), sampling.warnings.begin(), sampling.warnings.end());
    for (const std::string& w : warnings) std::cerr << "fretbuzz: warning: " << w << "\n";
    if (!(a.snapshot_rate_hz >= 0.0 && a.snapshot_rate_hz <= c.run.sample_rate_hz))
        throw InputError(out_of_range_message("--snapshots (Hz)", a.snapshot_rate_hz,
                                              "must be in [0, fs] (0 for none)"));
    if (a.snapshot_until_s) require_positive("--snapshot-until (s)", *a.snapshot_until_s);
    require_non_negative("--fade-in (s)", a.fades.in_s);
    require_non_negative("--fade-out (s)", a.fades.out_s);

    RunOutputs outputs(a.out, c,
                       {.velocity_audio = a.velocity_audio,
                        .snapshot_rate_hz = a.snapshot_rate_hz,
                        .snapshot_until_s = a.snapshot_until_s.value_or(std::numeric_limits<double>::infinity()),
                        .dense_contact_map = a.dense_contact_map,
                        .command_line = command_line(),
                        .fades = a.fades});

    RunOptions options;
    options.plan.screen_contacts = !a.no_screen;
    options.free_flight = !a.no_free_flight;
    const bool show_progress = !a.quiet && ::isatty(STDERR_FILENO);
    if (show_progress) options.progress = print_progress;
    if (!a.quiet)
        std::cerr << "fretbuzz: " << c.name << ": " << c.mode_count() << " modes, fs = " << c.run.sample_rate_hz
                  << " Hz, " << c.run.duration_s << " s\n";
    const RunSummary s = simulate(c, outputs.observers(), options);
    outputs.commit();
    if (show_progress) std::fputs("\r\033[K", stderr);
    if (!a.quiet) {
        std::cerr << "fretbuzz: " << s.steps << " steps in " << s.wall_seconds << " s ("
                  << s.wall_seconds / s.duration_s << " s per simulated second); " << s.contact_steps
                  << " steps with contact; energy " << s.energy_initial_j << " J -> " << s.energy_final_j
                  << " J" << (s.contact_law == "impact" ? "; the impacts took " + std::to_string(s.impact_loss_j) + " J" : "")
                  << "; outputs in " << outputs.path().string() << "\n";
    }
    if (a.report) return make_report(outputs.path(), a.quiet);
    if (!a.quiet)
        std::cerr << "fretbuzz: plots and an HTML report: fretbuzz report " << outputs.path().string() << "\n";
    return 0;
}

}  // namespace

void add_run_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<RunArguments>();
    CLI::App* cmd = app.add_subcommand("run", "Simulate a built-in case or a .toml case file");
    cmd->add_option("case", args->case_name, "Built-in case name (see `fretbuzz cases`) or path to a .toml file")
        ->required();
    cmd->add_option("--fs", args->fs, "Sampling rate Fe in Hz");
    cmd->add_option("--duration", args->duration, "Simulated duration in s");
    cmd->add_option("--K", args->stiffness, "Penalty stiffness K");
    cmd->add_option("--alpha", args->exponent, "Penalty exponent alpha (>= 1)");
    cmd->add_option("--law", args->law, "Contact law at the obstacle: penalty or impact (Newton's, rigid)");
    cmd->add_option("--restitution", args->restitution, "Impact law: Newton's restitution coefficient e in [0, 1]");
    cmd->add_flag("--lossless", args->lossless, "Remove all damping (sigma_j = 0)");
    cmd->add_flag("--allow-aliasing", args->allow_aliasing,
                  "Run even when modes lie so close to a multiple of fs that contact results are wrong "
                  "(as run.allow_aliasing = true)");
    cmd->add_option("--observe", args->observe, "Add an observation point x in m (repeatable)");
    cmd->add_option("--fret", args->fret,
                    "Stop the string with a finger just behind fret K (default finger: 5 g, 5 N after 5 ms)");
    cmd->add_option("--polarisations", args->polarisations,
                    "1: the string moves along z only; 2: along y (parallel to the fretboard) too");
    cmd->add_option("--angle", args->angle, "Direction of the initial shape in degrees from z toward y (needs 2 polarisations)");
    cmd->add_option("--pickup-angle", args->pickup_angle,
                    "Also write audio_pickup.wav: the displacement along this direction in degrees from z (2 polarisations)");
    cmd->add_option("--output-rate", args->output_rate, "Rows per second of the CSV outputs, or 'native'");
    cmd->add_option("--audio-rate", args->audio_rate, "Sample rate of the WAV files in Hz (default: the case's, 48000)");
    cmd->add_option("--fade-in", args->fades.in_s, "Raised-cosine fade-in of the WAV files in s (no click at the start)")
        ->capture_default_str();
    cmd->add_option("--fade-out", args->fades.out_s, "Raised-cosine fade-out of the WAV files in s")
        ->capture_default_str();
    cmd->add_flag("--velocity-audio", args->velocity_audio,
                  "Also write the velocity (what a magnetic pickup senses) as velocity*.wav");
    cmd->add_option("--snapshots", args->snapshot_rate_hz, "Store string shapes in results.h5 at this rate in Hz")
        ->capture_default_str();
    cmd->add_option("--snapshot-until", args->snapshot_until_s,
                    "Store string shapes only up to this time in s (e.g. the contacts of a pop)");
    cmd->add_flag("--report", args->report, "Then make the plots and report.html in the output directory");
    cmd->add_option("--out", args->out, "Output directory")->capture_default_str();
    cmd->add_flag("--no-screen", args->no_screen, "Solve contact at every grid point every step (slow reference)");
    cmd->add_flag("--no-free-flight", args->no_free_flight,
                  "Step every mode every step even when no contact is possible (audio exact to round-off, slower)");
    cmd->add_flag("--dense-contact-map", args->dense_contact_map,
                  "Also store the contact map densely in results.h5 (/contact/max_force_dense), to check readers");
    cmd->add_flag("-q,--quiet", args->quiet, "No progress or summary on stderr");
    cmd->callback([cmd, args, &action] {
        for (const char* name : {"--K", "--alpha", "--law", "--restitution", "--observe", "--fret", "--polarisations", "--angle",
                                 "--pickup-angle", "--fade-in", "--fade-out", "--velocity-audio", "--snapshots",
                                 "--snapshot-until", "--no-screen", "--no-free-flight", "--dense-contact-map"})
            if (cmd->count(name) > 0) args->one_string_only.emplace_back(name);
        action = [args] { return run_command(*args); };
    });
}

}  // namespace fretbuzz::cli
