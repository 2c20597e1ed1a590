#include "fretbuzz/model/ModeTableAssembly.hpp"

#include <optional>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

ModeTable assemble_mode_table(std::size_t mode_count, const std::vector<MeasuredMode>& measured,
                              const FrequencyModel* frequency, const ModalDamping* damping) {
    std::vector<std::optional<MeasuredMode>> by_mode(mode_count);
    for (const MeasuredMode& m : measured)
        if (m.mode >= 1 && m.mode <= mode_count) by_mode[m.mode - 1] = m;

    ModeTable table;
    for (std::size_t j = 1; j <= mode_count; ++j) {
        if (const auto& m = by_mode[j - 1]) {
            table.frequency_hz.push_back(m->frequency_hz);
            table.sigma_per_s.push_back(m->sigma_per_s);
            table.source.push_back(ModeSource::measured);
            continue;
        }
        if (frequency == nullptr)
            throw InputError("mode " + std::to_string(j) +
                             " is not measured and no frequency model is given ([modes.frequency])");
        const double nu = frequency->frequency_hz(j);
        table.frequency_hz.push_back(nu);
        table.sigma_per_s.push_back(damping != nullptr ? damping->sigma_per_s(j, nu) : 0.0);
        table.source.push_back(ModeSource::model);
    }
    table.validate();
    return table;
}

}  // namespace fretbuzz
