#include "fretbuzz/Error.hpp"

#include <atomic>
#include <cmath>
#include <csignal>
#include <sstream>
#include <string>

namespace fretbuzz {

namespace {
// Lock-free, so a signal handler may store into it.
std::atomic<int> requested_stop{0};
static_assert(std::atomic<int>::is_always_lock_free);
}  // namespace

Interrupted::Interrupted(int signal)
    : std::runtime_error(std::string("interrupted by ") + (signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "a signal")),
      signal_(signal) {}

void request_stop(int signal) noexcept { requested_stop.store(signal, std::memory_order_relaxed); }

int stop_signal() noexcept { return requested_stop.load(std::memory_order_relaxed); }

void throw_if_stopped() {
    if (const int signal = stop_signal(); signal != 0) throw Interrupted(signal);
}

std::string number_text(double value) {
    std::ostringstream out;
    out.precision(6);
    out << value;
    return out.str();
}

std::string out_of_range_message(const std::string& name, double value, const std::string& allowed) {
    std::ostringstream out;
    out.precision(17);
    out << name << " = " << value << " is out of range: " << allowed;
    return out.str();
}

void require_finite(const std::string& name, double value) {
    if (!std::isfinite(value)) throw InputError(out_of_range_message(name, value, "must be a finite number"));
}

void require_positive(const std::string& name, double value) {
    require_finite(name, value);
    if (!(value > 0.0)) throw InputError(out_of_range_message(name, value, "must be > 0"));
}

void require_at_least(const std::string& name, double value, double minimum) {
    require_finite(name, value);
    if (!(value >= minimum)) {
        std::ostringstream allowed;
        allowed << "must be >= " << minimum;
        throw InputError(out_of_range_message(name, value, allowed.str()));
    }
}

void require_non_negative(const std::string& name, double value) { require_at_least(name, value, 0.0); }

}  // namespace fretbuzz
