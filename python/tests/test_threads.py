"""Solves release the GIL: two threads solve two 50,000-member scenes in clearly less than
twice the time of one.

The library parallelises inside a solve with rayon; on a 2-core machine a solve that already
uses both cores cannot run beside another in less than twice its time, GIL or not. So the
timing runs in a child process whose solves use one thread each (RAYON_NUM_THREADS=1): what
is measured is then only whether two Python threads solve at once."""

import os
import subprocess
import sys
import textwrap

import linkage

CHILD = textwrap.dedent(
    """
    import threading, time
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
    started = time.perf_counter()
    a.run()
    one = time.perf_counter() - started
    results = {}
    threads = [threading.Thread(target=lambda s=s: results.update({s.name: s.run()})) for s in (a, b)]
    started = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    two = time.perf_counter() - started
    assert results["a"] == results["b"]
    print(f"{one} {two}")
    """
)


def test_two_threads_solve_two_50000_member_scenes_in_less_than_1_6_times_one():
    load = os.getloadavg()[0]
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    done = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    one, two = map(float, done.stdout.split())
    print(f"one scene {one:.2f} s; two scenes on two threads {two:.2f} s ({two / one:.2f}x one); load {load:.1f}")
    # 1.6x on a machine with its cores free; on a loaded machine (other builds running) the
    # two threads share the cores with them, and only "less than twice" is checked.
    limit = 1.6 if load < 1.0 else 1.95
    assert two < limit * one, f"two threads took {two:.2f} s, one scene {one:.2f} s (load {load:.1f})"


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
    ticks = 0
    solving.start()
    started = time.perf_counter()
    while solving.is_alive():
        ticks += 1
        time.sleep(0.001)
    solving.join()
    seconds = time.perf_counter() - started
    print(f"{ticks} ticks in {seconds:.2f} s of solving")
    assert seconds > 0.05 and ticks > 10
