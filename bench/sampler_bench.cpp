// What one number costs: the QMC stream (core/rng.h Rng) against the old PCG32 stream (Pcg32),
// drawn the way a camera path draws them (a stream per path; per bounce two pairs for next-event
// estimation, a pair and one number for the BSDF, one for roulette: core/sample_dims.h).
// Interleaved rounds (the machine is shared), median CPU ns per number, and user-space instructions
// per number from the CPU's counter where the kernel allows it (perf_event_open).
//
//   g++ -std=c++17 -O2 -Inative/src bench/sampler_bench.cpp -o /tmp/sampler_bench
//   /tmp/sampler_bench [bounces=8] [rounds=15]
// Instructions where perf_event_open is refused (containers): build with -g, then
//   valgrind --tool=callgrind /tmp/sampler_bench 3 1; callgrind_annotate --inclusive=yes ...
// and divide draw_path<...>'s count by 200000 paths x (2 + 8 x bounces) numbers.
#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/rng.h"

using namespace lantern;

namespace {

int open_instruction_counter() {
    perf_event_attr a;
    std::memset(&a, 0, sizeof(a));
    a.type = PERF_TYPE_HARDWARE;
    a.size = sizeof(a);
    a.config = PERF_COUNT_HW_INSTRUCTIONS;
    a.disabled = 1;
    a.exclude_kernel = 1;
    a.exclude_hv = 1;
    return int(syscall(__NR_perf_event_open, &a, 0, -1, -1, 0));
}

long long read_counter(int fd) {
    long long v = 0;
    if (fd < 0 || read(fd, &v, sizeof(v)) != sizeof(v)) return -1;
    return v;
}

// One path's numbers: the camera pair, then `bounces` bounces of 8 dimensions.
template <class Stream>
__attribute__((noinline)) float draw_path(Stream r, int bounces) {
    Vec2 p = r.uniform2();
    float acc = p.x + p.y;
    for (int b = 0; b < bounces; ++b) {
        Vec2 pick = r.uniform2(), light = r.uniform2(), dir = r.uniform2();
        acc += pick.x + light.x + light.y + dir.x + dir.y + r.uniform() + r.uniform();
    }
    return acc;
}

// This thread's CPU time: on a loaded machine wall time mostly measures the other processes.
double thread_cpu_ns() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e9 * double(ts.tv_sec) + double(ts.tv_nsec);
}

struct Result {
    double ns = 0.0;
    long long instructions = -1;
};

template <class Make>
Result run(Make make, int paths, int bounces, int fd, float* sink) {
    if (fd >= 0) {
        ioctl(fd, PERF_EVENT_IOC_RESET, 0);
        ioctl(fd, PERF_EVENT_IOC_ENABLE, 0);
    }
    const double t0 = thread_cpu_ns();
    float acc = 0.0f;
    for (int p = 0; p < paths; ++p) acc += draw_path(make(p), bounces);
    const double t1 = thread_cpu_ns();
    if (fd >= 0) ioctl(fd, PERF_EVENT_IOC_DISABLE, 0);
    *sink += acc;
    Result r;
    r.ns = t1 - t0;
    r.instructions = read_counter(fd);
    return r;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    const int bounces = argc > 1 ? std::atoi(argv[1]) : 8;
    const int rounds = argc > 2 ? std::atoi(argv[2]) : 15;
    const int paths = 200000;
    const double numbers = double(paths) * (2 + 8 * bounces);  // as drawn (skips not counted)
    const int fd = open_instruction_counter();
    float sink = 0.0f;
    std::vector<double> pcg_ns, qmc_ns, pcg_in, qmc_in;
    for (int k = 0; k < rounds; ++k) {
        Result a = run([](int p) { return Pcg32::for_path(7, 3, uint64_t(p)); }, paths, bounces,
                       fd, &sink);
        Result b = run([](int p) { return Rng::for_camera(7, 3, 16, p); }, paths, bounces, fd,
                       &sink);
        pcg_ns.push_back(a.ns / numbers);
        qmc_ns.push_back(b.ns / numbers);
        pcg_in.push_back(double(a.instructions) / numbers);
        qmc_in.push_back(double(b.instructions) / numbers);
    }
    std::printf("%d paths x (1 + %d bounces x 8) draws, %d interleaved rounds, kQmcDims %u\n",
                paths, bounces, rounds, kQmcDims);
    std::printf("| stream | CPU ns / number (median) | min | instructions / number |\n");
    std::printf("|---|---|---|---|\n");
    auto row = [&](const char* name, const std::vector<double>& ns, const std::vector<double>& in) {
        char ins[32] = "n/a";
        if (fd >= 0) std::snprintf(ins, sizeof(ins), "%.1f", median(in));
        std::printf("| %s | %.2f | %.2f | %s |\n", name, median(ns),
                    *std::min_element(ns.begin(), ns.end()), ins);
    };
    row("Pcg32", pcg_ns, pcg_in);
    row("Rng (QMC)", qmc_ns, qmc_in);
    std::fprintf(stderr, "(sink %g)\n", double(sink));
    return 0;
}
