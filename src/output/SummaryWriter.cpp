#include "fretbuzz/output/SummaryWriter.hpp"

#include <nlohmann/json.hpp>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "JsonText.hpp"

namespace fretbuzz {

std::string summary_json(const RunSummary& s, const std::vector<double>& observation_points_m, const Case* c,
                         const SummaryExtras* extras) {
    nlohmann::ordered_json json = {
        {"case", s.case_name},
        {"fs", s.sample_rate_hz},
        {"duration", s.duration_s},
        {"steps", s.steps},
        {"modes", s.modes},
        {"modes_choice", s.mode_choice},
        {"output_rate", s.output_rate_hz},
        {"wall_seconds", s.wall_seconds},
        {"steps_per_second", s.steps_per_second},
        {"lossless", s.lossless},
        {"contact_screening", s.screened},
        {"contact_screening_choice", s.screening},
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
    if (extras != nullptr) {
        // One entry per WAV file: a sample of 1.0 stands for full_scale (m, or m/s for velocity).
        nlohmann::ordered_json audio = nlohmann::ordered_json::array();
        for (const AudioWriter* writer : extras->audio)
            for (std::size_t p = 0; p < writer->paths().size(); ++p)
                audio.push_back({{"file", writer->paths()[p].filename().string()},
                                 {"x_m", p < observation_points_m.size() ? observation_points_m[p] : 0.0},
                                 {"signal", writer->signal() == AudioSignal::velocity ? "velocity" : "displacement"},
                                 {"full_scale", writer->full_scale(p)},
                                 {"full_scale_unit", writer->signal() == AudioSignal::velocity ? "m/s" : "m"},
                                 {"rate_hz", writer->rate_hz()},
                                 {"fade_in_s", writer->fades().in_s},
                                 {"fade_out_s", writer->fades().out_s}});
        if (!audio.empty()) json["audio"] = audio;
        if (extras->provenance && c != nullptr)
            json["provenance"] = nlohmann::ordered_json::parse(provenance_json(*extras->provenance, *c));
    }
    if (s.fingers + s.gestures > 0) {  // the balance is then energy - work + dissipated = energy_initial
        json["fingers"] = s.fingers;
        json["gestures"] = s.gestures;
        json["finger_contact_steps"] = s.finger_contact_steps;
        json["work_J"] = s.work_j;
        json["finger_energy_final_J"] = s.finger_energy_final_j;
        json["finger_loss_J"] = s.finger_loss_j;
        json["damping_dissipated_J"] = s.dissipated_j - s.finger_loss_j - s.friction_j;  // along z and y
    }
    if (s.contact_law == "impact") {  // dissipated_J holds the impacts' losses too
        json["contact_law"] = s.contact_law;
        json["restitution"] = s.restitution;
        json["impact_loss_J"] = s.impact_loss_j;
        json["damping_dissipated_J"] = s.dissipated_j - s.impact_loss_j;
    }
    if (s.polarisations == 2) {  // energy_final_J and dissipated_J hold these terms too
        json["polarisations"] = 2;
        json["energy_z_final_J"] = s.energy_final_j - s.energy_y_final_j - s.finger_energy_final_j;  // with contact
        json["energy_y_final_J"] = s.energy_y_final_j;
        json["damping_z_J"] = s.dissipated_j - s.finger_loss_j - s.damping_y_j - s.friction_j;
        json["damping_y_J"] = s.damping_y_j;
        json["friction_dissipated_J"] = s.friction_j;
        json["max_friction_iterations"] = s.max_friction_iterations;
    }
    return json_text(json, 2);
}

void SummaryWriter::finish(const RunSummary& s) {
    write_text_file(path_, summary_json(s, observation_points_m_, case_, &extras_) + '\n');
}

}  // namespace fretbuzz
