#pragma once
// Each mode's partials settled on the whole decay's spectrum: one partial, a resolved
// doublet (the string's two polarisations) or a doublet too close to resolve, reported as
// one merged partial. ESPRIT's poles per band start it; then, mode by mode with every
// neighbour's leakage subtracted (DecaySpectrum), the mode's bins are fitted by nonlinear
// least squares (maximum likelihood in white noise) with one partial and with two, and
//  - detection: two partials only where the second lowers the residual significantly: the
//    likelihood-ratio statistic 2 (R_1 - R_2) / E|noise|^2, chi-square with 4 degrees of
//    freedom for a single partial, must reach `doublet_detection` (40: a chance of 4e-8 for
//    one try; the best of several starts makes it larger, still small);
//  - resolution: the two are resolved only if their frequency difference is at least
//    `resolution_sd` times its own Cramer-Rao standard deviation. Smith (IEEE Trans. Signal
//    Process. 53(5), 2005) defines the statistical resolution limit as the separation equal
//    to its Cramer-Rao standard deviation (`resolution_sd` = 1); that deviation grows as
//    (Delta f T)^-2 to (Delta f T)^-3 below one beat in the record (Lee, IEEE Trans. Signal
//    Process. 40(6), 1992), so the rule takes Delta f T, the mode's SNR and the model (both
//    partials, every amplitude and the background fitted jointly) into account at once.
//    A detected pair below it is reported as the one-partial fit, `merged`: its damping is
//    that of the beating envelope;
//  - reliability: a partial is reliable when its damping's Cramer-Rao standard deviation
//    (the same joint fit's) is at most `reliable_sigma_sd` of it: an efficient estimate is
//    then within 5 standard deviations, 15 % at 0.03, and its frequency far closer (the
//    two deviations are equal in alpha and theta, so f's relative one is 1/(2Q) of sigma's;
//    Yao & Pandit, IEEE Trans. Signal Process. 42(7), 1994). Merged partials never are.
#include <cstddef>
#include <vector>

#include "fretbuzz/analysis/DecaySpectrum.hpp"
#include "fretbuzz/analysis/ModalEstimation.hpp"
#include "fretbuzz/analysis/ModelFit.hpp"

namespace fretbuzz {

// `partials` (by mode, then polarisation, as ESPRIT found them) are replaced by the settled
// ones, with their standard deviations and flags; a mode whose fit fails (it does not
// converge, or leaves a partial growing, outside its bins or below the least Q) is dropped.
// Returns the number of partials dropped.
std::size_t resolve_doublets(std::vector<EstimatedPartial>& partials, const DecaySpectrum& spectrum, double rate_hz,
                             const FrequencyLaw& law, const EstimationOptions& options);

}  // namespace fretbuzz
