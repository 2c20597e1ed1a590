// Running a sweep: one run (with its obstacle-free reference) into one row, and all the
// missing rows of a sweep on a pool of threads.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/analysis/BuzzMetrics.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/sweep/Sweep.hpp"
#include "fretbuzz/sweep/SweepStore.hpp"

namespace fretbuzz {

const std::vector<std::string>& sweep_metric_names() {
    static const std::vector<std::string> names = {
        "contact_steps",      "touched_points",        "touched_x_min_m",      "touched_x_max_m",
        "features_touched",   "main_feature",          "first_contact_s",      "last_contact_s",
        "contact_episodes",   "contact_time_s",        "contact_energy_loss_J", "peak_contact_force_N",
        "contact_impulse_Ns", "hf_energy_m2",          "hf_energy_free_m2",    "hf_energy_contact_m2",
        "hf_change_dB",       "buzz_dB",
        "energy_initial_J",   "energy_final_J",        "max_relative_energy_balance_error"};
    return names;
}

namespace {

BuzzReport run_with_metrics(const Case& c, double band_hz, RunSummary* summary, const std::filesystem::path& audio_dir,
                            std::vector<double>* signal) {
    BuzzMetrics metrics(band_hz);
    std::vector<RunObserver*> observers{&metrics};
    std::unique_ptr<AudioWriter> audio;
    if (!audio_dir.empty()) {
        std::filesystem::create_directories(audio_dir);
        std::vector<std::filesystem::path> paths;
        for (const std::string& name : audio_file_names(AudioSignal::displacement, c.observation_points_m))
            paths.push_back(audio_dir / name);
        audio = std::make_unique<AudioWriter>(paths, c.run.audio_rate_hz);
        observers.push_back(audio.get());
    }
    const RunSummary s = simulate(c, observers);
    if (summary != nullptr) *summary = s;
    if (signal != nullptr) *signal = metrics.signal();
    return metrics.report();
}

std::string features_text(const std::vector<std::size_t>& features) {
    std::string text;
    for (std::size_t f : features) {
        if (!text.empty()) text += ' ';
        text += std::to_string(f);
    }
    return text;
}

}  // namespace

SweepRow run_sweep_point(const SweepSpec& spec, std::size_t index, const std::filesystem::path& audio_dir) {
    if (index >= spec.runs.size())
        throw InputError("sweep run " + std::to_string(index) + " does not exist (the sweep has " +
                         std::to_string(spec.runs.size()) + " runs)");
    const SweepRun run = spec.runs[index];
    SweepRow row;
    row.index = index;
    for (const SweepValue& v : run.values) row.values.push_back(v.text);
    row.metrics.assign(sweep_metric_names().size(), BuzzReport::nan);
    const auto start = std::chrono::steady_clock::now();
    try {
        RunSummary summary;
        std::vector<double> u, u_free;
        const Case c = sweep_case(spec, run);
        const BuzzReport b = run_with_metrics(c, spec.buzz_band_hz, &summary, audio_dir, &u);
        const BuzzReport free = run_with_metrics(obstacle_free_case(spec, run), spec.buzz_band_hz, nullptr, {}, &u_free);
        // What the contacts added to the signal: u - u_free, sample by sample (the same
        // case and rates). Without contact it is round-off of two paths: no buzz (NaN).
        double contact_hf = b.contact_steps == 0 ? 0.0 : BuzzReport::nan;
        if (b.contact_steps > 0 && u.size() == u_free.size()) {
            for (std::size_t i = 0; i < u.size(); ++i) u[i] -= u_free[i];
            contact_hf = high_frequency_energy(u, summary.output_rate_hz, spec.buzz_band_hz);
        }
        row.metrics = {static_cast<double>(b.contact_steps),
                       static_cast<double>(b.touched_points),
                       b.touched_x_min_m,
                       b.touched_x_max_m,
                       static_cast<double>(b.touched_features.size()),
                       static_cast<double>(b.main_feature),
                       b.first_contact_s,
                       b.last_contact_s,
                       static_cast<double>(b.episodes),
                       b.contact_time_s,
                       b.energy_lost_in_contact_j,
                       b.peak_force_n,
                       b.impulse_n_s,
                       b.high_frequency_energy,
                       free.high_frequency_energy,
                       contact_hf,
                       buzz_level_db(b.high_frequency_energy, free.high_frequency_energy),
                       buzz_level_db(contact_hf, free.high_frequency_energy),
                       summary.energy_initial_j,
                       summary.energy_final_j,
                       summary.max_relative_balance_error};
        row.features = features_text(b.touched_features);
        row.ok = true;
    } catch (const Interrupted&) {
        throw;  // not a failed run: the sweep stops and the run is left for --resume
    } catch (const std::exception& e) {
        row.ok = false;
        row.error = e.what();
    }
    row.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return row;
}

std::string row_to_json(const SweepRow& row) {
    nlohmann::ordered_json metrics = nlohmann::ordered_json::object();
    for (std::size_t k = 0; k < row.metrics.size(); ++k) {
        const double v = row.metrics[k];
        metrics[sweep_metric_names()[k]] = std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json();
    }
    const nlohmann::ordered_json json = {{"index", row.index},     {"values", row.values},
                                         {"ok", row.ok},           {"error", row.error},
                                         {"features", row.features}, {"metrics", metrics},
                                         {"wall_seconds", row.wall_seconds}};
    return json.dump();
}

SweepRow row_from_json(const std::string& text) {
    SweepRow row;
    try {
        const nlohmann::json json = nlohmann::json::parse(text);
        row.index = json.at("index").get<std::size_t>();
        row.values = json.at("values").get<std::vector<std::string>>();
        row.ok = json.at("ok").get<bool>();
        row.error = json.at("error").get<std::string>();
        row.features = json.at("features").get<std::string>();
        row.wall_seconds = json.at("wall_seconds").get<double>();
        const auto& metrics = json.at("metrics");
        for (const std::string& name : sweep_metric_names()) {
            const auto it = metrics.find(name);
            row.metrics.push_back(it == metrics.end() || it->is_null() ? BuzzReport::nan : it->get<double>());
        }
    } catch (const nlohmann::json::exception& e) {
        throw InputError(std::string("sweep row: not a row of this fretbuzz (") + e.what() + ")");
    }
    return row;
}

SweepOutcome run_sweep(const SweepSpec& spec, const std::filesystem::path& out, const SweepOptions& options) {
    check_sweep(spec, options.checking, options.jobs);  // every value, before anything is written
    const SweepStore store(spec, out, options.resume);
    const std::vector<std::size_t> todo = store.missing();
    SweepOutcome outcome;
    outcome.total = spec.runs.size();
    outcome.resumed = outcome.total - todo.size();
    for (const SweepRow& row : store.rows_present()) outcome.failed += row.ok ? 0 : 1;
    const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
    outcome.jobs = static_cast<unsigned>(
        std::max<std::size_t>(1, std::min<std::size_t>(todo.size(), options.jobs ? options.jobs : hardware)));

    const auto start = std::chrono::steady_clock::now();
    std::atomic<std::size_t> next{0};
    std::mutex mutex;  // guards outcome, failure and the progress callback
    std::exception_ptr failure;
    auto worker = [&] {
        for (std::size_t k = next++; k < todo.size(); k = next++) {
            if (options.stop && options.stop()) {
                std::lock_guard lock(mutex);
                outcome.interrupted = true;
                next = todo.size();
                break;
            }
            try {
                const std::size_t index = todo[k];
                const SweepRow row = run_sweep_point(spec, index, spec.audio ? store.audio_dir(index) : std::filesystem::path{});
                store.record(row);
                std::lock_guard lock(mutex);
                ++outcome.computed;
                if (!row.ok) ++outcome.failed;
                if (options.progress) {
                    SweepProgress p;
                    p.total = outcome.total;
                    p.done = outcome.resumed + outcome.computed;
                    p.failed = outcome.failed;
                    p.resumed = outcome.resumed;
                    p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                    p.remaining_s = p.elapsed_s / static_cast<double>(outcome.computed) *
                                    static_cast<double>(todo.size() - outcome.computed);
                    options.progress(p);
                }
            } catch (const Interrupted& e) {
                // Ctrl-C or SIGTERM: the runs under way stop at their next step; the finished
                // rows stay for --resume.
                std::lock_guard lock(mutex);
                outcome.interrupted = true;
                outcome.signal = e.signal();
                next = todo.size();
            } catch (...) {
                std::lock_guard lock(mutex);
                if (!failure) failure = std::current_exception();
                next = todo.size();  // an I/O failure stops the sweep; finished rows stay
            }
        }
    };
    {
        std::vector<std::jthread> workers;
        for (unsigned t = 0; t < outcome.jobs; ++t) workers.emplace_back(worker);
    }
    outcome.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (failure) std::rethrow_exception(failure);
    if (outcome.interrupted) return outcome;
    store.write_table();
    outcome.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return outcome;
}

}  // namespace fretbuzz
