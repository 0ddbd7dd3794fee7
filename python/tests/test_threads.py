"""The GIL is released while seethru renders; Ctrl-C (SIGINT) stops a long render."""

import os
import signal
import threading
import time

import pytest

import seethru
from conftest import SCENE


def test_a_python_thread_runs_while_a_render_runs():
    scene = seethru.Scene.load(SCENE)
    scene.render("truth", width=16, spp=1)  # builds the world first
    ticks = 0
    stop = threading.Event()

    def count():
        nonlocal ticks
        while not stop.is_set():
            ticks += 1
            time.sleep(0.001)

    thread = threading.Thread(target=count)
    start = time.perf_counter()
    thread.start()
    time.sleep(0.01)
    before = ticks
    scene.render("truth", width=640, spp=16)
    elapsed = time.perf_counter() - start
    during = ticks - before
    stop.set()
    thread.join()
    # A held GIL would freeze the counter for the whole render; released, it ticks at
    # about 1 kHz (a slow, busy machine: a tenth of that is plenty).
    assert elapsed > 0.1, "the render was too short to tell"
    assert during > 20, f"{during} ticks in {elapsed:.2f} s"


def test_sigint_interrupts_a_long_render():
    # Python turns SIGINT into KeyboardInterrupt only if SIGINT was not ignored when it
    # started; a shell's background job (`cmd &`) starts with it ignored.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _interrupt_a_long_render()
    finally:
        signal.signal(signal.SIGINT, previous)


def _interrupt_a_long_render():
    scene = seethru.Scene.load(SCENE)
    scene.render("truth", width=16, spp=1)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        # A minute or more of work in bands of 4 rows × 1920 pixels × 128 samples (a band
        # takes well under a second: the render stops after the band it is in).
        scene.render("truth", width=1920, spp=128)
    elapsed = time.perf_counter() - start
    timer.join()
    assert elapsed < 20, f"the render stopped only after {elapsed:.1f} s"
    # The next render is whole again (the cancellation was lifted).
    small = scene.render("truth", width=32, spp=1)
    assert (small.object_id > 0).any()
