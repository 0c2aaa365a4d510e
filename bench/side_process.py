"""One side of a Lantern-against-Cycles comparison in a process of its own (benchproc).

In a bpy process an idle worker thread of bpy's TBB spins in sched_yield all through a
one-thread Cycles render (Cycles waits in a task arena of one thread; the worker keeps looking
for work): Cycles' process CPU time reads 1.0-2.0x the render thread's, by how much of a CPU
the machine leaves free, and on a busy machine the spinner takes wall time from the render
thread too (bench/results/2026-12-05-benchproc/). Lantern in the same process (its Embree
loads the same libtbb.so.12) adds its own threads to the process's time. A benchmark that
times both therefore renders each side in a child process confined to one CPU (`one_cpu`:
TBB then starts no worker): `Side` starts one (a script's --serve mode) and sends it requests
one at a time, so that the seeds can still be interleaved between the sides; the child answers
on a pipe of its own (Blender prints to stdout). Requests and answers are JSON objects; images
travel as .npy files named in them."""
import json
import os
import subprocess
import sys
import traceback


class Side:
    """A child process `python argv... --reply-fd N` serving requests (see `serve`)."""

    def __init__(self, argv, quiet=True):
        r, w = os.pipe()
        self.proc = subprocess.Popen([sys.executable, *argv, "--reply-fd", str(w)],
                                     stdin=subprocess.PIPE, text=True, pass_fds=(w,),
                                     stdout=subprocess.DEVNULL if quiet else None)
        os.close(w)
        self.replies = os.fdopen(r, "r")
        self.ready = self._reply()  # the child's first answer: set-up done (or its error)

    def _reply(self):
        line = self.replies.readline()
        if not line:
            raise RuntimeError(f"side process {self.proc.args[1:3]} ended (exit status "
                               f"{self.proc.wait()})")
        msg = json.loads(line)
        if "error" in msg:
            raise RuntimeError(msg["error"])
        return msg

    def call(self, **request):
        self.proc.stdin.write(json.dumps(request) + "\n")
        self.proc.stdin.flush()
        return self._reply()

    def close(self):
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait()
        self.replies.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def serve(reply_fd, setup, handle):
    """The child's loop: `setup()` once (its dict the first answer), then `handle(request)` per
    line of stdin; an exception is answered as {"error": ...}."""
    out = os.fdopen(reply_fd, "w")

    def answer(fn, *a):
        try:
            msg = fn(*a) or {}
        except Exception as e:  # noqa: BLE001 -- the parent reports it
            msg = {"error": f"{type(e).__name__}: {e}\n{traceback.format_exc()[-1500:]}"}
        out.write(json.dumps(msg) + "\n")
        out.flush()
        return "error" not in msg

    if not answer(setup):
        return
    for line in sys.stdin:
        answer(handle, json.loads(line))


def one_cpu():
    """Confine this process to one CPU (the lowest it may use). Call it before bpy or lantern
    loads TBB: TBB sizes its worker pool by the affinity mask, and with one CPU it starts no
    worker to spin (see the module's docstring); a one-thread render loses nothing by it."""
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
