// The queue that writes results.h5's chunks beside the run: writes land in order, and a
// failed write is never lost (the run learns of it and commits nothing), whatever the timing.
#include <gtest/gtest.h>

#include <atomic>
#include <span>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "fretbuzz/run/WriteQueue.hpp"
#include "../src/run/PerStepQueue.hpp"

namespace fretbuzz {
namespace {

TEST(WriteQueue, RunsEveryJobInOrderBeforeDrainReturns) {
    std::vector<int> done;
    WriteQueue queue;
    for (int k = 0; k < 1000; ++k) queue.post([&done, k] { done.push_back(k); });  // more than it holds at once
    queue.drain();
    ASSERT_EQ(done.size(), 1000u);
    for (int k = 0; k < 1000; ++k) EXPECT_EQ(done[static_cast<std::size_t>(k)], k);
}

// Per-step frames in batches, with deferred jobs (a flight's frames, made on the queue's thread)
// and posted ones between them: the sink sees every frame in the order the run made it.
struct FrameLog {
    void every_step(std::span<const double> u, std::span<const double>) { seen.push_back(u[0]); }
    std::vector<double> seen;
};

TEST(PerStepQueue, DeferredJobsRunInTheirPlaceAmongTheFrames) {
    FrameLog log;
    std::vector<double> expected;
    {
        PerStepQueue queue([&log](const double* u, const double*, std::size_t count) {
            log.seen.insert(log.seen.end(), u, u + count);
        }, 1, false);
        double next = 0.0;
        for (int round = 0; round < 50; ++round) {
            for (int k = 0; k < 300 * (round % 4); ++k) {  // runs of frames, some empty
                const double u[] = {next};
                queue.frame(u, {});
                expected.push_back(next++);
            }
            // A deferred job making frames of its own (a flight's), sometimes several in a row.
            for (int j = 0; j <= round % 3; ++j) {
                const double first = next;
                const int frames = 1000 + 37 * round;
                queue.defer(
                    [&log, first, frames] {
                        for (int k = 0; k < frames; ++k) {
                            const double u[] = {first + k};
                            log.every_step(u, {});
                        }
                    },
                    static_cast<std::size_t>(frames));
                for (int k = 0; k < frames; ++k) expected.push_back(next++);
            }
            if (round % 7 == 0) queue.post([] {});  // a posted job flushes the batch
        }
        queue.drain();
    }
    ASSERT_EQ(log.seen.size(), expected.size());
    EXPECT_EQ(log.seen, expected);
}

TEST(WriteQueue, AFailedWriteIsRethrownAndTheWritesAfterItAreDropped) {
    std::atomic<int> after{0};
    WriteQueue queue;
    queue.post([] { throw std::runtime_error("cannot write results.h5: No space left on device"); });
    // Whether the failure is met by a later post or by drain depends on timing; it is met once.
    bool thrown = false;
    try {
        for (int k = 0; k < 200; ++k) queue.post([&after] { ++after; });
        queue.drain();
    } catch (const std::runtime_error& e) {
        thrown = true;
        EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos);
    }
    EXPECT_TRUE(thrown);
    EXPECT_THROW(queue.drain(), std::runtime_error);  // still failed: nothing may be committed
    EXPECT_EQ(after.load(), 0) << "writes after a failure must not run (they would write past a hole)";
}

TEST(WriteQueue, DestroyedMidRunItWaitsForTheRunningWriteOnly) {
    std::atomic<int> started{0}, finished{0};
    {
        WriteQueue queue;
        for (int k = 0; k < 10; ++k)
            queue.post([&] {
                ++started;
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
                ++finished;
            });
        while (started.load() == 0) std::this_thread::yield();
    }  // a run that failed elsewhere: the queued writes are dropped, the running one completes
    EXPECT_EQ(started.load(), finished.load());
    EXPECT_LT(finished.load(), 10);
}

}  // namespace
}  // namespace fretbuzz
