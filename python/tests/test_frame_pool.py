"""Recycled frame buffers and `Scene.render(..., out=frame)`: the same bits as a fresh render,
never a buffer Python can still see, and refusals with their reasons."""

import threading
import time

import numpy as np
import pytest

import seethru
from conftest import SCENE

NAMES = ["colour", "depth", "camera_z", "position", "normal", "object_id", "part_id"]
WIDTH = 96


def bits(frame):
    """Copies of every array of a frame, as bytes (NaN equal to itself, -0.0 unequal to 0.0)."""
    return {name: np.ascontiguousarray(getattr(frame, name)).tobytes() for name in NAMES}


def assert_same_bits(frame, want, what):
    got = bits(frame)
    for name in NAMES:
        assert got[name] == want[name], f"{what}: {frame.view}.{name} differs"


def scribble(frame):
    """Writes values no render gives into every array (they are the user's, and writable)."""
    for name in NAMES:
        a = getattr(frame, name)
        a[...] = 12345 if a.dtype == np.uint32 else -7.5


def moved(scene, dx):
    x, y, z = scene.eye
    scene.eye = (x + dx, y, z)
    return scene


def spans(frame):
    """The byte ranges of every buffer of a frame."""
    return [(a.ctypes.data, a.ctypes.data + a.nbytes) for a in (getattr(frame, n) for n in NAMES)]


def overlaps(a, b):
    return any(s < e2 and s2 < e for s, e in a for s2, e2 in b)


@pytest.fixture
def scene():
    scene = seethru.Scene.load(SCENE)
    scene.render("truth", width=8, spp=1)  # builds the world once
    seethru.frame_pool(clear=True)
    return scene


def test_out_writes_the_bits_of_a_fresh_render_in_place(scene):
    frame = scene.render("truth", width=WIDTH, spp=2)
    view_of_depth = frame.depth[::2]  # a numpy view the user took before
    addresses = {n: getattr(frame, n).ctypes.data for n in NAMES}
    moved(scene, 0.05)
    fresh = scene.render("truth", width=WIDTH, spp=2)
    assert bits(fresh) != bits(frame), "the eye moved: the two renders must differ"
    scribble(frame)  # nothing of what the frame held may survive the render
    returned = scene.render("truth", width=WIDTH, spp=2, out=frame)
    assert returned is frame
    assert_same_bits(frame, bits(fresh), "out=")
    # In place: the same buffers, and views of them see the new render.
    assert {n: getattr(frame, n).ctypes.data for n in NAMES} == addresses
    assert view_of_depth.tobytes() == np.ascontiguousarray(fresh.depth[::2]).tobytes()


def test_a_recycled_buffer_renders_the_same_bits_as_a_new_one(scene):
    dropped = scene.render("truth", width=WIDTH, spp=1)
    old = dropped._buffer_addresses
    scribble(dropped)
    del dropped  # its buffers go to the pool, holding what the user wrote
    moved(scene, -0.07)
    recycled = scene.render("truth", width=WIDTH, spp=1)
    assert recycled._buffer_addresses == old, "the dropped frame's buffers were not reused"
    seethru.frame_pool(clear=True)
    new = scene.render("truth", width=WIDTH, spp=1)  # nothing to recycle: new buffers
    assert not overlaps(spans(new), spans(recycled))
    assert_same_bits(recycled, bits(new), "recycled")


def test_a_recycled_buffer_never_aliases_a_frame_or_array_still_alive(scene):
    first = scene.render("truth", width=WIDTH, spp=1)
    moved(scene, 0.03)
    second = scene.render("truth", width=WIDTH, spp=1)
    colour_only = scene.render("truth", width=WIDTH, spp=1).colour  # the frame is gone, one array is not
    part_view = scene.render("truth", width=WIDTH, spp=1).part_id[5:9]  # only a slice is left
    held = [bits(first), bits(second), colour_only.tobytes(), part_view.tobytes()]
    live = spans(first) + spans(second) + [
        (colour_only.ctypes.data, colour_only.ctypes.data + colour_only.nbytes),
        (part_view.ctypes.data, part_view.ctypes.data + part_view.nbytes),
    ]
    dropped = scene.render("truth", width=WIDTH, spp=1)
    reused = dropped._buffer_addresses
    del dropped
    for dx in (0.1, -0.2, 0.3):
        moved(scene, dx)
        third = scene.render("truth", width=WIDTH, spp=1)
        assert not overlaps(spans(third), live), "a new render was given a buffer Python holds"
        assert third._buffer_addresses == reused  # the pool is used, from what was dropped
        del third
    assert_same_bits(first, held[0], "first")
    assert_same_bits(second, held[1], "second")
    assert colour_only.tobytes() == held[2]
    assert part_view.tobytes() == held[3]


def test_the_pool_is_bounded_and_can_be_emptied(scene):
    info = seethru.frame_pool()
    assert info["max_frames"] >= 2 and info["max_bytes"] >= 2 * 640 * 360 * 52
    for width in range(16, 16 + 3 * info["max_frames"]):
        scene.render("frontal", width=width, spp=1)
        info = seethru.frame_pool()
        assert info["frames"] <= info["max_frames"] and info["bytes"] <= info["max_bytes"]
    assert info["frames"] == info["max_frames"]
    assert seethru.frame_pool(clear=True)["frames"] == 0
    assert seethru.frame_pool()["bytes"] == 0


def test_out_refusals_name_the_reason(scene):
    frame = scene.render("truth", width=WIDTH, spp=1)
    before = bits(frame)
    with pytest.raises(ValueError, match=r'out: the frame is a "truth" view and this render is "occluded"'):
        scene.render("occluded", width=WIDTH, spp=1, out=frame)
    with pytest.raises(ValueError, match=r"out: the frame is 96×54 and this render is 48×27 \(width×height\)"):
        scene.render("truth", width=WIDTH // 2, spp=1, out=frame)
    frame.normal.flags.writeable = False  # the user's own mark: this array must not change
    with pytest.raises(ValueError, match=r"out: frame.normal is read-only \(its flags.writeable is False\)"):
        scene.render("truth", width=WIDTH, spp=1, out=frame)
    assert_same_bits(frame, before, "a refused out=")
    cap = seethru.capture(scene, width=32, frontal_width=64, back_width=32, spp=1)
    with pytest.raises(ValueError, match="out: this frontal frame's arrays are read-only views of a capture"):
        scene.render("frontal", width=64, spp=1, out=cap.frontal)
    with pytest.raises(TypeError):
        scene.render("truth", width=WIDTH, spp=1, out=frame.colour)


def test_two_renders_into_one_frame_at_once_refuse_one(scene):
    frame = scene.render("truth", width=640, spp=1)
    for _ in range(5):
        outcome = {}

        def render(who, spp):
            start = time.perf_counter()
            try:
                scene.copy().render("truth", width=640, spp=spp, out=frame)
                outcome[who] = (start, time.perf_counter(), None)
            except ValueError as e:
                outcome[who] = (start, time.perf_counter(), str(e))

        long = threading.Thread(target=render, args=("long", 64))
        long.start()
        time.sleep(0.05)
        render("short", 1)
        long.join()
        (s1, e1, err1), (s2, e2, err2) = outcome["long"], outcome["short"]
        if err1 is None and err2 is None and (e1 < s2 or e2 < s1):
            continue  # they did not overlap: try again
        errors = [e for e in (err1, err2) if e is not None]
        assert len(errors) == 1, f"overlapping renders into one frame: {errors}"
        assert errors[0].startswith("out: frame.colour is in use by another call")
        return
    pytest.fail("the two renders never overlapped")


def test_a_frame_is_read_only_to_python_while_a_render_writes_it(scene):
    frame = scene.render("truth", width=640, spp=1)
    done = threading.Event()

    def render():
        scene.copy().render("truth", width=640, spp=64, out=frame)
        done.set()

    worker = threading.Thread(target=render)
    worker.start()
    refused = 0
    while not done.is_set():
        try:
            frame.colour[0, 0, 0] = 0.5
        except ValueError as e:
            assert "read-only" in str(e)
            refused += 1
        time.sleep(0.001)
    worker.join()
    assert refused > 0, "a plain write raced with the render"
    # Writable again once the render has returned.
    frame.colour[0, 0, 0] = 0.5
    assert all(getattr(frame, a).flags.writeable for a in ("colour", "position", "normal", "depth", "camera_z", "object_id", "part_id"))
