"""Where the CPU time of a one-thread Cycles render goes, per thread, with and without Lantern
in the same process (benchproc; bench/results/2026-12-05-ptfog2/ found Cycles' process CPU
time at twice its wall time after Lantern's renders in bench/automedia_cycles.py).

One fresh bpy process per call (--pin: on one CPU from the start): build `--scene`
(bench/automedia_cycles.py's SCENES), then, by --mode, nothing else (alone: `lantern` never
imported), `import lantern` and the add-on (import), or that and --sessions pt Sessions of
--lantern-spp rendered and deleted (session; --keep keeps the last alive), then --renders
Cycles renders (render_compare.render_cycles, threads FIXED 1). Each thread's user+system CPU
seconds (/proc/self/task/*/stat; threads that end during the render read every 0.1 s) over
each render are printed with where the thread first appeared, the process CPU and wall
seconds of the render and the libtbb files mapped; --stacks takes gdb's backtraces once a
thread that was there before the render is busy in it. Run inside bpy's Python:

    nice -n 10 python bench/cycles_thread_probe.py --mode session --scene lamp_shade_soft \\
        --spp 256 --out bench/results/2026-12-05-benchproc/probe.txt"""
import argparse
import gc
import os
import platform
import subprocess
import sys
import threading
import time

if "--pin" in sys.argv:  # before bpy loads TBB: its worker count follows the affinity mask
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import automedia_cycles as ac  # noqa: E402  (adds python/, tests/cycles, tools; no lantern)
import render_compare as rc  # noqa: E402

TICK = os.sysconf("SC_CLK_TCK")


def threads():
    """{tid: (name, cpu seconds)} of this process's live threads."""
    out = {}
    for tid in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{tid}/stat") as f:
                s = f.read()
        except OSError:
            continue
        name = s[s.index("(") + 1:s.rindex(")")]
        rest = s[s.rindex(")") + 2:].split()
        out[int(tid)] = (name, (int(rest[11]) + int(rest[12])) / TICK)  # utime, stime
    return out


def emitter(out):
    def emit(line):
        print(line, flush=True)
        with open(out, "a") as f:
            f.write(line + "\n")
    return emit


def tbb_maps():
    with open("/proc/self/maps") as f:
        return sorted({ln.split()[-1] for ln in f if "tbb" in ln and "/" in ln})


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="lamp_shade_soft", choices=list(ac.SCENES))
    ap.add_argument("--mode", choices=["alone", "import", "session"], default="alone")
    ap.add_argument("--keep", action="store_true", help="keep the Lantern Session alive")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--lantern-spp", type=int, default=64)
    ap.add_argument("--sessions", type=int, default=1, help="pt Sessions rendered in turn")
    ap.add_argument("--renders", type=int, default=1, help="Cycles renders in turn")
    ap.add_argument("--pin", action="store_true", help="this process on one CPU from the start")
    ap.add_argument("--stacks", help="file for gdb's backtraces of all threads, taken once "
                    "when a thread that was there before the Cycles render is busy in it")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import bpy
    emit = emitter(args.out)
    emit(f"# {' '.join(sys.argv)}; LANTERN_THREADS={os.environ.get('LANTERN_THREADS')}")
    emit(f"# {platform.node()} {platform.machine()}, {os.cpu_count()} cores, load "
         f"{os.getloadavg()[0]:.1f}")
    ac.SCENES[args.scene]()
    bpy.context.scene.render.threads_mode, bpy.context.scene.render.threads = "FIXED", 1
    live = None
    born = {tid: "bpy" for tid in threads()}  # where each thread first appeared

    def tag(stage):
        for tid in threads():
            born.setdefault(tid, stage)
    if args.mode != "alone":
        import lantern
        rc.lantern_bpy.load_addon()
        from lantern_blender.export import export_scene
        scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        tag("lantern import+export")
        for k in range(args.sessions if args.mode == "session" else 0):
            c0, w0 = time.process_time(), time.perf_counter()
            s = lantern.Session(scene, integrator="pt", backend="cpu", threads=1, seed=1 + k,
                                spp_per_iteration=1, max_depth=rc.lantern_depth(rc.BOUNCES))
            while s.spp < args.lantern_spp:
                s.step()
            emit(f"lantern pt {args.lantern_spp} spp: CPU {time.process_time() - c0:.2f} s, "
                 f"wall {time.perf_counter() - w0:.2f} s; threads {len(threads())}")
            tag(f"pt Session {k + 1}")
            if args.keep:
                live = s
            del s
            gc.collect()
    emit(f"lantern imported: {'lantern' in sys.modules}; tbb mapped: {tbb_maps()}")
    emit(f"affinity {sorted(os.sched_getaffinity(0))}")
    for r in range(args.renders):
        tag("before Cycles")
        before = threads()
        after, done = dict(before), threading.Event()

        def poll():  # threads that end during the render: their last reading every 0.1 s
            t0, dumped = time.perf_counter(), not args.stacks
            while not done.wait(0.1):
                after.update(threads())
                busy = [tid for tid in before if after[tid][1] - before[tid][1] > 0.5]
                if not dumped and busy and time.perf_counter() - t0 > 2.0:
                    dumped = True  # a thread that was there before the render is busy in it
                    bt = subprocess.run(["gdb", "-p", str(os.getpid()), "-batch", "-ex",
                                         "thread apply all bt 12"], capture_output=True, text=True)
                    with open(args.stacks, "w") as f:
                        f.write(f"busy threads (LWP) {busy}\n" + bt.stdout)
        poller = threading.Thread(target=poll, name="probe-poll")
        poller.start()
        c0, w0 = time.process_time(), time.perf_counter()
        rc.render_cycles(seed=900 + r, spp=args.spp)
        cpu, wall = time.process_time() - c0, time.perf_counter() - w0
        done.set()
        poller.join()
        after.update(threads())
        emit(f"cycles {args.spp} spp: process CPU {cpu:.2f} s, wall {wall:.2f} s, "
             f"CPU/wall {cpu / wall:.2f}; threads before {len(before)}, after {len(after)}")
        seen = 0.0
        for tid, (name, t) in sorted(after.items()):
            d = t - before.get(tid, (name, 0.0))[1]
            seen += d
            if d >= 0.05:
                emit(f"  thread {tid} {name!r} {born.get(tid, 'new in the render')}: "
                     f"{d:.2f} CPU s")
        emit(f"  unaccounted (the last 0.1 s of ended threads): {cpu - seen:.2f} CPU s; "
             f"tbb mapped: {tbb_maps()}; live Session {live is not None}")


if __name__ == "__main__":
    main()
