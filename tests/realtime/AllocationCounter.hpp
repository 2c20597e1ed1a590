#pragma once
// Counts heap allocations (malloc, calloc, realloc and everything built on them, operator new
// included) made by this thread while a Counting scope is alive: the real-time tests check
// that the audio path makes none.
namespace fretbuzz::testing {

long allocations();  // made inside Counting scopes since the program started

class Counting {
public:
    Counting();
    ~Counting();
    Counting(const Counting&) = delete;
    Counting& operator=(const Counting&) = delete;
};

}  // namespace fretbuzz::testing
