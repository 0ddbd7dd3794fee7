"""seethru.capture's arrays: read-only views of the capture's own buffers, no copy."""

import numpy as np
import pytest

import seethru
from conftest import SCENE

SIZES = dict(width=96, frontal_width=128, back_width=96, spp=1)


def test_capture_arrays_view_the_capture_buffers_read_only():
    scene = seethru.Scene.load(SCENE)
    cap = seethru.capture(scene, depth=True, **SIZES)
    for frame in (cap.frontal, cap.back):
        for name, address in frame._buffer_addresses.items():
            a = getattr(frame, name)
            # No copy: numpy's data pointer is the Rust buffer's, owned by the capture.
            assert a.__array_interface__["data"][0] == address, name
            assert not a.flags.owndata and type(a.base).__name__ == "_CaptureBuffers", name
            assert not a.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            frame.colour[0, 0, 0] = 1.0
        with pytest.raises(ValueError):
            frame.colour.flags.writeable = True
    d = cap.inverse_depth
    assert d is not None and not d.flags.owndata and not d.flags.writeable
    # The frontal and back views share one owner, the capture that score reads.
    assert cap.frontal.colour.base is cap.back.depth.base is d.base
    assert np.shares_memory(cap.frontal.colour, cap.frontal.colour[::2])
    # A view outlives the capture object that made it: the owner is its base.
    colour = cap.frontal.colour
    expected = colour.copy()
    del cap
    import gc
    gc.collect()
    assert np.array_equal(colour, expected, equal_nan=True)
