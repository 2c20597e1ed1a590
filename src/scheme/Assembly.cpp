#include "fretbuzz/scheme/Assembly.hpp"

namespace fretbuzz {

namespace {
template <class Term>
double sum(const std::vector<VibratingString>& strings, Term term) {
    double e = 0.0;
    for (const VibratingString& s : strings) e += term(s);
    return e;
}
}  // namespace

double Assembly::energy() const { return sum(strings_, [](const VibratingString& s) { return s.energy(); }); }
double Assembly::dissipated() const { return sum(strings_, [](const VibratingString& s) { return s.dissipated(); }); }
double Assembly::work() const { return sum(strings_, [](const VibratingString& s) { return s.work(); }); }

}  // namespace fretbuzz
