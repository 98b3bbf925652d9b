"""Long calls release the GIL, report progress through the callback, and
stop on Ctrl-C (SIGINT), on _thread.interrupt_main() from another thread and
on hairvox.interrupt(), raising KeyboardInterrupt and leaving no output."""

import _thread
import os
import signal
import threading
import time

import pytest

import hairvox
from conftest import small_scene

# A render that would take minutes: the path tracer at a million samples.
LONG = {"integrator": "path", "spp": 1_000_000}


def long_scene(tmp_path):
    return small_scene(output={"exr": str(tmp_path / "long.exr"), "png": str(tmp_path / "long.png")})


def after(seconds, action):
    timer = threading.Timer(seconds, action)
    timer.start()
    return timer


@pytest.mark.parametrize("how", ["sigint", "interrupt_main", "hairvox.interrupt"])
def test_an_interrupted_render_raises_keyboard_interrupt_and_leaves_no_output(tmp_path, how):
    action = {
        "sigint": lambda: os.kill(os.getpid(), signal.SIGINT),
        "interrupt_main": _thread.interrupt_main,
        "hairvox.interrupt": hairvox.interrupt,
    }[how]
    timer = after(0.5, action)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        hairvox.render(long_scene(tmp_path), **LONG)
    elapsed = time.monotonic() - start
    timer.join()
    assert 0.4 < elapsed < 10, f"stopped after {elapsed:.2f} s"
    assert list(tmp_path.iterdir()) == [], "an interrupted render left files"
    # The next call starts afresh.
    assert hairvox.render(small_scene()).layers["beauty"].shape == (64, 64, 4)


def test_an_interrupted_dual_scattering_render_stops_between_chunks(tmp_path):
    # The default scene (20,000 strands) on one thread, stopped while it loads
    # or splats: the stages poll the flag.
    timer = after(0.3, _thread.interrupt_main)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        hairvox.render(width=512, height=512, threads=1)
    timer.join()
    assert time.monotonic() - start < 20
    assert list(tmp_path.iterdir()) == []


def test_the_gil_is_released_while_rendering():
    ticks = 0
    stop = threading.Event()

    def count():
        nonlocal ticks
        while not stop.is_set():
            ticks += 1
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    try:
        start = time.monotonic()
        hairvox.render(small_scene(), integrator="path", spp=64, threads=1)
        elapsed = time.monotonic() - start
    finally:
        stop.set()
        counter.join()
    # Python code ran on another thread during the render.
    assert elapsed > 0.05 and ticks > 10, (elapsed, ticks)


def test_progress_reaches_the_callback_on_the_calling_thread():
    calls = []
    caller = threading.get_ident()

    def progress(stage, done, total):
        assert threading.get_ident() == caller
        calls.append((stage, done, total))

    hairvox.render(small_scene(), integrator="path", spp=256, threads=1, progress=progress)
    stages = [c for c in calls if c[0] == "path trace"]
    assert len(stages) >= 2, calls
    done = [d for _, d, _ in stages]
    assert done == sorted(done) and done[-1] == stages[-1][2], "not monotone or not finished"


def test_an_exception_in_the_callback_stops_the_render_and_propagates():
    class Stop(Exception):
        pass

    def progress(stage, done, total):
        raise Stop(stage)

    start = time.monotonic()
    with pytest.raises(Stop):
        hairvox.render(small_scene(), **LONG, progress=progress)
    assert time.monotonic() - start < 10


def test_a_render_interrupted_in_a_worker_thread_by_hairvox_interrupt():
    result = {}

    def work():
        try:
            hairvox.render(small_scene(), **LONG)
        except KeyboardInterrupt as e:
            result["raised"] = e

    worker = threading.Thread(target=work)
    worker.start()
    time.sleep(0.5)
    hairvox.interrupt()
    worker.join(10)
    assert not worker.is_alive() and "raised" in result
