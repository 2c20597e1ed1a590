#include "fretbuzz/scheme/PlayedParts.hpp"

#include <utility>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/ForceProfile.hpp"

namespace fretbuzz {

namespace {
// The plan's fingers (its specs, in order), on its grid and obstacle.
std::vector<Finger> fingers_of(const Plan& plan) {
    std::vector<Finger> fingers;
    fingers.reserve(plan.fingers().size());
    for (const FingerSpec& spec : plan.fingers())
        fingers.emplace_back(spec, plan.basis().grid_step(), plan.obstacle(), plan.contact(), plan.dt(),
                             plan.force_to_displacement());
    return fingers;
}

// At its exact position, each plucker's scalar equation is the whole contact solve of a step
// where it acts alone, else it is one more equation in the system of the exact points, the other
// pluckers, the grid's obstacle points and the fingers (PointContact).
std::vector<Pluck> plucks_of(const Plan& plan) {
    std::vector<Pluck> plucks;
    plucks.reserve(plan.plucks().size());
    for (const PluckSpec& spec : plan.plucks())
        plucks.emplace_back(spec, pad_mean_shapes(plan.basis(), spec.position_m, spec.width_m), plan.dt(),
                            plan.force_to_displacement());
    return plucks;
}
}  // namespace

PlayedParts::PlayedParts(const Plan& plan)
    : fingers_(fingers_of(plan)), plucks_(plucks_of(plan)), on_pad_(plan.mode_count(), 0) {
    link();
    on_.assign(parts_.size(), 1);
    std::size_t k = 0;  // the parts are in the specs' order
    for (const FingerSpec& spec : plan.fingers()) claim(parts_[k++]->pad(), spec.key, plan.basis());
    for (const PluckSpec& spec : plan.plucks()) claim(parts_[k++]->pad(), spec.key, plan.basis());
}

PlayedParts::PlayedParts(const PlayedParts& other)
    : fingers_(other.fingers_), plucks_(other.plucks_), on_(other.on_), on_pad_(other.on_pad_), pad_points_(other.pad_points_) {
    link();
}

void PlayedParts::link() {
    parts_.clear();
    for (Finger& f : fingers_) parts_.push_back(&f);
    for (Pluck& p : plucks_) parts_.push_back(&p);
}

void PlayedParts::claim(const std::vector<std::size_t>& pad, const std::string& key, const ModalBasis& basis) {
    for (std::size_t i : pad) {
        if (on_pad_[i] != 0)
            throw InputError(key + ": it acts on x = " + std::to_string(basis.grid_point(i)) +
                             " m where another finger or gesture acts; they must not overlap");
        on_pad_[i] = 1;
    }
    pad_points_ += pad.size();
}

bool PlayedParts::hold(const std::vector<std::size_t>& pad) {
    for (std::size_t i : pad)
        if (on_pad_[i] != 0) return false;
    for (std::size_t i : pad) on_pad_[i] = 1;
    pad_points_ += pad.size();
    return true;
}

void PlayedParts::release(const std::vector<std::size_t>& pad) {
    for (std::size_t i : pad) on_pad_[i] = 0;
    pad_points_ -= pad.size();
}

bool PlayedParts::fingers_on() const {
    for (std::size_t f = 0; f < fingers_.size(); ++f)
        if (on(f)) return true;
    return false;
}

double PlayedParts::energy() const {
    double e = 0.0;
    for (const PlayedPart* part : parts_) e += part->energy();
    return e;
}

double PlayedParts::work() const {
    double e = 0.0;
    for (const PlayedPart* part : parts_) e += part->work();
    return e;
}

double PlayedParts::loss() const {
    double e = 0.0;
    for (const PlayedPart* part : parts_) e += part->loss();
    return e;
}

}  // namespace fretbuzz
