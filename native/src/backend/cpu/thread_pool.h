// A small fork-join pool for the CPU backend: parallel_for hands out fixed-size chunks of an
// index range; the caller's thread works too. Which thread runs a chunk never changes a result
// (stages write only their own slots). A worker reads a job's parameters once, under the lock,
// and claims chunks only of the job it checked in for (claims carry the job's generation), so a
// late worker can never run chunks of the next job with the last one's grain. A parallel_for
// called from inside a job (nested) runs inline on the calling thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace lantern {

class ThreadPool {
public:
    // threads: 0 = hardware concurrency. Throws std::system_error when a thread cannot be
    // started, after stopping and joining the ones it did start.
    explicit ThreadPool(int threads);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    int size() const { return int(workers_.size()) + 1; }
    // Calls fn(begin, end) over [0, n) in chunks of `grain`; returns when all are done.
    // One caller at a time (the pool serialises concurrent callers).
    void parallel_for(int n, int grain, const std::function<void(int, int)>& fn);

private:
    struct Job {
        const std::function<void(int, int)>* fn = nullptr;
        int n = 0, grain = 1;
        uint32_t generation = 0;
    };
    void worker();
    void run_chunks(const Job& job);
    void stop_and_join();

    std::vector<std::thread> workers_;
    std::mutex mutex_;        // guards job_, busy_, stop_
    std::mutex caller_;       // one parallel_for at a time
    std::condition_variable wake_, done_;
    Job job_;
    // high 32 bits: the generation of the job whose chunks are handed out; low 32: next index
    std::atomic<uint64_t> next_{0};
    int busy_ = 0;
    bool stop_ = false;
};

}  // namespace lantern
