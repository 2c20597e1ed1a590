#pragma once
// Errors fretbuzz reports to its users. InputError always names the parameter
// at fault and what would have been accepted; the CLI prints it and exits 2.
#include <stdexcept>
#include <string>

namespace fretbuzz {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A numerical failure during a run (e.g. a contact solve that did not converge).
class SolverError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A run stopped by a signal (SIGINT, SIGTERM) at a step boundary; nothing was written.
class Interrupted : public std::runtime_error {
public:
    explicit Interrupted(int signal);
    int signal() const { return signal_; }

private:
    int signal_;
};

// Asks running simulations to stop at their next step boundary (async-signal-safe: a
// signal handler may call it). stop_signal() is the signal asked for, 0 if none.
void request_stop(int signal) noexcept;
int stop_signal() noexcept;
// Throws Interrupted if a stop was asked for.
void throw_if_stopped();

// A number as messages quote it: six significant digits.
std::string number_text(double value);

// Formats "<name> = <value> is out of range: <allowed>" for InputError messages.
std::string out_of_range_message(const std::string& name, double value, const std::string& allowed);

// Throws InputError unless value is finite and satisfies the predicate.
void require_finite(const std::string& name, double value);
void require_positive(const std::string& name, double value);
void require_at_least(const std::string& name, double value, double minimum);
void require_non_negative(const std::string& name, double value);

}  // namespace fretbuzz
