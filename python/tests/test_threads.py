"""Solves release the GIL: two threads solve two 50,000-member scenes in clearly less than
twice the time of one (the best of a few back-to-back measurements, both solves overlapping
and using more CPU than wall time), and a Python thread keeps running during a solve.

The library parallelises inside a solve with rayon; on a 2-core machine a solve that already
uses both cores cannot run beside another in less than twice its time, GIL or not. So the
timing runs in a child process whose solves use one thread each (RAYON_NUM_THREADS=1): what
is measured is then only whether two Python threads solve at once."""

import json
import os
import subprocess
import sys
import textwrap

import linkage

CHILD = textwrap.dedent(
    """
    import json, threading, time
    import linkage

    def big_scene(name):
        # 125 x 100 cells of a braced rectangle: 50,225 members; large displacements, so each
        # step is a Newton solve with a factorization per iteration.
        steel = linkage.Material("steel", youngs_modulus=200e9, area=1e-4)
        body = linkage.Body("plate", rectangle={"width": 1.25, "height": 1.0, "cells": [125, 100]},
                            material=steel, kinematics="large", solver="direct")
        body.support(on_line={"point": [0.0, 0.0], "direction": [0.0, 1.0]}, fix=["x", "y"])
        body.load(on_line={"point": [1.25, 0.0], "direction": [0.0, 1.0]}, total_force=[0.0, -2e5])
        return linkage.Scene(name, bodies=[body], steps=2)

    a, b = big_scene("a"), big_scene("b")
    assert "50225 members" in a.describe(), a.describe()
    a.run()  # warm: page in the code and the allocator
    attempts = []
    # One solve, then two on two threads, measured back to back so that both see the same
    # load of the machine; again until two take less than 1.6x one, at most 5 times.
    for attempt in range(5):
        started, cpu = time.perf_counter(), time.process_time()
        a.run()
        one, one_cpu = time.perf_counter() - started, time.process_time() - cpu
        results, spans = {}, {}
        def solve(s):
            begun = time.perf_counter()
            results[s.name] = s.run()
            spans[s.name] = (begun, time.perf_counter())
        threads = [threading.Thread(target=solve, args=(s,)) for s in (a, b)]
        started, cpu = time.perf_counter(), time.process_time()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        two, two_cpu = time.perf_counter() - started, time.process_time() - cpu
        assert results["a"] == results["b"]
        overlap = min(e for _, e in spans.values()) - max(s for s, _ in spans.values())
        shorter = min(e - s for s, e in spans.values())
        attempts.append({"one": one, "one_cpu": one_cpu, "two": two, "two_cpu": two_cpu,
                         "overlap": overlap / shorter})
        if two < 1.6 * one:
            break
    print(json.dumps(attempts))
    """
)


def test_two_threads_solve_two_50000_member_scenes_in_less_than_1_6_times_one():
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    done = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    attempts = json.loads(done.stdout)
    for k, t in enumerate(attempts):
        print(f"attempt {k + 1}: one scene {t['one']:.2f} s ({t['one_cpu']:.2f} s CPU); two scenes on two "
              f"threads {t['two']:.2f} s ({t['two']/t['one']:.2f}x one, {t['two_cpu']:.2f} s CPU, "
              f"solves overlapping {100 * t['overlap']:.0f}%); load {os.getloadavg()[0]:.1f}")
    best = min(attempts, key=lambda t: t["two"] / t["one"])
    # The two solves ran at the same time, not one after the other...
    assert best["overlap"] > 0.8, best
    # ...and two cores worked at once: CPU time per wall second was more than 1.3x that of
    # one solve (a GIL held through a solve keeps one solving thread at a time: 1x). A ratio,
    # not an absolute, because on a machine loaded by other work each thread gets its fair
    # share of the cores: one solve then gets less than a core, two get about twice that...
    parallelism = (best["two_cpu"] / best["two"]) / (best["one_cpu"] / best["one"])
    assert parallelism > 1.3, (parallelism, best)
    # ...so that two scenes took clearly less than twice one, in the best of up to 5
    # back-to-back measurements (a loaded machine slows single attempts).
    assert best["two"] < 1.6 * best["one"], best


def test_a_solve_lets_other_python_threads_run():
    # While a scene solves on one thread, this thread keeps counting: the GIL is free.
    import threading
    import time

    steel = linkage.Material("steel", youngs_modulus=200e9, area=1e-4)
    body = linkage.Body("plate", rectangle={"width": 1.0, "height": 1.0, "cells": [60, 60]},
                        material=steel, kinematics="large", solver="direct")
    body.support(on_line={"point": [0.0, 0.0], "direction": [0.0, 1.0]}, fix=["x", "y"])
    body.load(on_line={"point": [1.0, 0.0], "direction": [0.0, 1.0]}, total_force=[0.0, -2e5])
    scene = linkage.Scene("plate", bodies=[body], steps=4)
    solving = threading.Thread(target=scene.run)
    ticks, gap = 0, 0.0
    solving.start()
    started = last = time.perf_counter()
    while solving.is_alive():
        ticks += 1
        time.sleep(0.001)
        now = time.perf_counter()
        gap, last = max(gap, now - last), now
    solving.join()
    seconds = time.perf_counter() - started
    print(f"{ticks} ticks in {seconds:.2f} s of solving (4 steps); largest gap {gap * 1e3:.1f} ms")
    # A GIL held through a step would stop this thread for a whole step (a quarter of the
    # solve); released, it only waits for the scheduler.
    assert seconds > 0.05 and ticks > 10
    assert gap < 0.1 * seconds, f"this thread stood still {gap:.3f} s of {seconds:.3f} s"
