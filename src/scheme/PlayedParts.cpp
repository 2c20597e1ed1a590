#include "fretbuzz/scheme/PlayedParts.hpp"

#include <utility>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/ForceProfile.hpp"

namespace fretbuzz {

namespace {
// The plan's played parts of one kind (its specs, in order), built on its grid and obstacle.
template <class Part, class Spec>
std::vector<Part> parts_of(const Plan& plan, const std::vector<Spec>& specs) {
    std::vector<Part> parts;
    parts.reserve(specs.size());
    for (const Spec& spec : specs)
        parts.emplace_back(spec, plan.basis().grid_step(), plan.obstacle(), plan.contact(), plan.dt(),
                           plan.force_to_displacement());
    return parts;
}

// At their exact positions (plucks_exact), each plucker's scalar equation is the whole contact
// solve of a step where it acts alone, else it is one more equation in the system of the exact
// points, the other pluckers, the grid's obstacle points and the fingers (PointContact). Force
// gestures load the string explicitly.
std::vector<Pluck> plucks_of(const Plan& plan) {
    if (!plucks_exact(plan.plucks().size())) return parts_of<Pluck>(plan, plan.plucks());
    std::vector<Pluck> plucks;
    plucks.reserve(plan.plucks().size());
    for (const PluckSpec& spec : plan.plucks())
        plucks.emplace_back(spec, pad_mean_shapes(plan.basis(), spec.position_m, spec.width_m), plan.contact(), plan.dt(),
                            plan.force_to_displacement());
    return plucks;
}
}  // namespace

PlayedParts::PlayedParts(const Plan& plan)
    : fingers_(parts_of<Finger>(plan, plan.fingers())), plucks_(plucks_of(plan)), on_pad_(plan.mode_count(), 0) {
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
