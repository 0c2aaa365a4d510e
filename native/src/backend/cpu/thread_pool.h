// A small fork-join pool for the CPU backend: parallel_for hands out fixed-size chunks of an
// index range; the caller's thread works too. Which thread runs a chunk never changes a result
// (stages write only their own slots).
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace lantern {

class ThreadPool {
public:
    explicit ThreadPool(int threads);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    int size() const { return int(workers_.size()) + 1; }
    // Calls fn(begin, end) over [0, n) in chunks of `grain`; returns when all are done.
    void parallel_for(int n, int grain, const std::function<void(int, int)>& fn);

private:
    void worker();
    void run_chunks();

    std::vector<std::thread> workers_;
    std::mutex mutex_;
    std::condition_variable wake_, done_;
    const std::function<void(int, int)>* job_ = nullptr;
    int n_ = 0, grain_ = 1;
    std::atomic<int> next_{0};
    int busy_ = 0;
    uint64_t generation_ = 0;
    bool stop_ = false;
};

}  // namespace lantern
