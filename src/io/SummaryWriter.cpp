#include "fretbuzz/io/SummaryWriter.hpp"

#include <nlohmann/json.hpp>

#include "fretbuzz/io/CsvWriters.hpp"

namespace fretbuzz {

std::string summary_json(const RunSummary& s, const std::vector<double>& observation_points_m) {
    const nlohmann::ordered_json json = {
        {"case", s.case_name},
        {"fs", s.sample_rate_hz},
        {"duration", s.duration_s},
        {"steps", s.steps},
        {"modes", s.modes},
        {"output_rate", s.output_rate_hz},
        {"wall_seconds", s.wall_seconds},
        {"steps_per_second", s.steps_per_second},
        {"lossless", s.lossless},
        {"contact_screening", s.screened},
        {"energy_initial_J", s.energy_initial_j},
        {"energy_final_J", s.energy_final_j},
        {"dissipated_J", s.dissipated_j},
        {"max_relative_energy_increase", s.max_relative_energy_increase},
        {"max_relative_energy_balance_error", s.max_relative_balance_error},
        {"contact_steps", s.contact_steps},
        {"first_contact_s", s.first_contact_s},
        {"last_contact_s", s.last_contact_s},
        {"max_newton_iterations", s.max_newton_iterations},
        {"mean_points_solved_per_step", s.mean_points_solved},
        {"free_flight_fraction", s.free_flight_fraction},
        {"observation_points_m", observation_points_m},
        {"warnings", s.warnings},
    };
    return json.dump(2);
}

void SummaryWriter::finish(const RunSummary& s) {
    write_text_file(path_, summary_json(s, observation_points_m_) + '\n');
}

}  // namespace fretbuzz
