"""Ctrl-C during a long solve raises KeyboardInterrupt within a second, also inside one long
step; the solve thread then stops after its step."""

import _thread
import os
import signal
import threading
import time

import pytest

import linkage


def long_scene(steps: int, cells: int) -> linkage.Scene:
    steel = linkage.Material("steel", youngs_modulus=200e9, area=1e-4)
    body = linkage.Body("plate", rectangle={"width": 1.0, "height": 1.0, "cells": [cells, cells]},
                        material=steel, kinematics="large", solver="direct")
    body.support(on_line={"point": [0.0, 0.0], "direction": [0.0, 1.0]}, fix=["x", "y"])
    body.load(on_line={"point": [1.0, 0.0], "direction": [0.0, 1.0]}, total_force=[0.0, -2e5])
    return linkage.Scene("long", bodies=[body], steps=steps)


@pytest.fixture(autouse=True)
def python_handles_sigint():
    """Python's own SIGINT handler for the test. A process started with SIGINT ignored (a
    background job of a non-interactive shell, as CI may start it) gets no handler from
    Python, and then neither SIGINT nor `_thread.interrupt_main` raises KeyboardInterrupt:
    both tests failed that way, in a clean clone run in the background and once before."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def interrupted_after(scene: linkage.Scene, seconds: float, send) -> float:
    """Send the interrupt `seconds` after `scene.run()`'s solve thread started, while it still
    runs (never after it ended: a stray signal would stop a later test); the delay until
    KeyboardInterrupt, s."""
    sent = []

    def later():
        deadline = time.perf_counter() + 60.0
        while not linkage.running() and time.perf_counter() < deadline:
            time.sleep(0.002)
        time.sleep(seconds)
        if linkage.running():
            sent.append(time.perf_counter())
            send()

    threading.Thread(target=later, daemon=True).start()
    with pytest.raises(KeyboardInterrupt):
        scene.run()
    assert sent, "the run finished before the interrupt was sent: make the scene longer"
    return time.perf_counter() - sent[0]


def wait_for_solves_to_stop():
    deadline = time.perf_counter() + 60.0
    while linkage.running() and time.perf_counter() < deadline:
        time.sleep(0.05)
    assert linkage.running() == 0, "a solve thread went on after the interrupt"


def test_interrupt_main_arrives_within_a_second_between_many_steps():
    delay = interrupted_after(long_scene(steps=400, cells=40), 0.5, _thread.interrupt_main)
    print(f"KeyboardInterrupt {delay * 1e3:.0f} ms after the interrupt")
    assert delay < 1.0
    wait_for_solves_to_stop()


def test_sigint_arrives_within_a_second_inside_one_long_step():
    scene = long_scene(steps=1, cells=300)
    delay = interrupted_after(scene, 0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    print(f"KeyboardInterrupt {delay * 1e3:.0f} ms after SIGINT")
    assert delay < 1.0
    wait_for_solves_to_stop()
