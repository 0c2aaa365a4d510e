#include "backend/cpu/thread_pool.h"

#include <algorithm>

namespace lantern {

namespace {
thread_local const ThreadPool* t_inside = nullptr;  // the pool whose job this thread runs

struct InsideJob {
    const ThreadPool* saved;
    explicit InsideJob(const ThreadPool* p) : saved(t_inside) { t_inside = p; }
    ~InsideJob() { t_inside = saved; }
};
}  // namespace

ThreadPool::ThreadPool(int threads) {
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    try {
        for (int k = 1; k < threads; ++k) workers_.emplace_back([this] { worker(); });
    } catch (...) {
        stop_and_join();  // the threads already started must not outlive the pool
        throw;
    }
}

ThreadPool::~ThreadPool() { stop_and_join(); }

void ThreadPool::stop_and_join() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
    workers_.clear();
}

// Claims chunks of `job` until its range is exhausted or a newer job owns the counter.
void ThreadPool::run_chunks(const Job& job) {
    InsideJob inside(this);
    const uint64_t tag = uint64_t(job.generation) << 32;
    uint64_t cur = next_.load(std::memory_order_relaxed);
    for (;;) {
        if ((cur & ~uint64_t(0xffffffffu)) != tag) return;  // another job's counter
        const int begin = int(uint32_t(cur));
        if (begin >= job.n) return;
        const int end = std::min(job.n, begin + job.grain);
        if (!next_.compare_exchange_weak(cur, tag | uint32_t(end), std::memory_order_acq_rel,
                                         std::memory_order_relaxed))
            continue;  // cur now holds the fresh value
        (*job.fn)(begin, end);
        cur = next_.load(std::memory_order_relaxed);
    }
}

void ThreadPool::worker() {
    uint32_t seen = 0;
    for (;;) {
        Job job;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || job_.generation != seen; });
            if (stop_) return;
            job = job_;  // read once, under the lock
            seen = job.generation;
            ++busy_;
        }
        run_chunks(job);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (--busy_ == 0) done_.notify_all();
        }
    }
}

void ThreadPool::parallel_for(int n, int grain, const std::function<void(int, int)>& fn) {
    if (n <= 0) return;
    grain = std::max(1, grain);
    if (workers_.empty() || n <= grain || t_inside == this) {
        fn(0, n);  // small, single-threaded, or nested inside one of this pool's jobs
        return;
    }
    std::lock_guard<std::mutex> one_caller(caller_);
    Job job;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        job.fn = &fn;
        job.n = n;
        job.grain = grain;
        job.generation = job_.generation + 1;
        if (job.generation == 0) job.generation = 1;  // 0 is "no job yet" for a new worker
        job_ = job;
        next_.store(uint64_t(job.generation) << 32, std::memory_order_release);
    }
    wake_.notify_all();
    run_chunks(job);
    // Every chunk is claimed; wait until the workers that checked in have finished theirs.
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return busy_ == 0; });
}

}  // namespace lantern
