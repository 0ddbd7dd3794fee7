"""seethru from Python: scenes, renders and see-through runs as numpy arrays.

The package wraps the same library as the ``seethru`` command line: a scene read by
:meth:`Scene.load` renders the same pixels as ``seethru render`` and a :func:`run` computes the
same metrics as ``seethru run`` (bit for bit, for the same scene and options), without files
in between. Rendering releases the GIL and runs on the library's thread pool (all cores, or
``RAYON_NUM_THREADS``); Ctrl-C stops a long render between bands of rows.

Errors raise :class:`ValueError` (bad input: a scene key, an option's range) or
:class:`OSError` (a file that cannot be read) with the command line's one-line message.
"""

from ._native import Capture, Frame, Run, Scene, __version__, analyze, capture, compare, frame_pool, load_capture, options, ratio, read_frame, spec
from ._native import run as _run
from ._native import dataset as _dataset
from ._native import score as _score
from ._native import Sequence, Step
from ._native import sequence as _sequence

import numpy as _np

__all__ = [
    "Capture", "Frame", "Run", "Scene", "analyze", "capture", "compare", "dataset", "frame_pool", "load_capture", "options", "ratio", "read_frame", "run", "spec",
    "score", "sequence", "Sequence", "Step", "__version__",
]


def run(scene: Scene, **options) -> Run:
    """Runs the see-through system on ``scene``, as ``seethru run`` does.

    The keywords are ``seethru run``'s flags with ``_`` for ``-``, with the same types,
    defaults and ranges: the library's option table, listed by :func:`options` and in
    docs/reference/options.md. ``None`` stands for the default. An unknown keyword, or one the
    other settings make the run ignore, is refused with the command line's words; so is
    ``eyes="both"`` (one call is one run: run "left" and "right").
    :func:`spec` checks the keywords without running.

    Returns a :class:`Run`: ``frames`` (the six views), ``metrics`` (metrics.json's content),
    ``report`` (run.json's content), ``misregistration`` and ``missing`` (driver-view maps).
    """
    return _run(scene, **options)


def score(
    capture: Capture,
    map=None,
    display_image=None,
    filter: str = "bilinear",
    band: int = 5,
    display_codes: bool = False,
) -> Run:
    """Measures a method's display as ``seethru score`` does, without files.

    ``map``: (display height, display width, 2), per display pixel the frontal pixel it shows
    ([..., 0] = x, [..., 1] = y, OpenCV's ``remap`` convention; NaN shows nothing).
    ``display_image``: (display height, display width, 3) linear RGB shown instead of the
    map's colours (alone: image metrics only); with ``display_codes=True``, the display's
    codes in [0, 1], which its transfer curve (the scene's ``display_transfer``) turns into
    light. Any float array (or torch tensor via ``.numpy()``); it is read as float32. Returns
    a :class:`Run` like :func:`run`.
    """
    as_f32 = lambda a: None if a is None else _np.ascontiguousarray(a, dtype=_np.float32)
    return _score(capture, as_f32(map), as_f32(display_image), filter, band, display_codes)


def sequence(scene: Scene, predictor=None, **options) -> Sequence:
    """A sequence (``seethru sequence``) as an iterator of measured frames (:class:`Step`).

    The frames are made by the library's stepper, the one ``seethru sequence`` drives. The
    keywords are that command's flags for the simulated loop, in snake case, with the same
    defaults, ranges and refusals (a keyword the others make it ignore raises ValueError,
    e.g. ``sway_cm`` without ``head="sway"``):

    - timing: ``duration`` (s), ``fps``, ``display_hz`` (Hz); ``latency_camera`` (ms, a
      number or a list: the sequences of every latency one after the other, each
      :class:`Step` naming its ``latency_camera``), ``latency_tracking`` (ms);
    - vehicle: ``speed`` (km/h), ``yaw_rate`` (deg/s);
    - head motion: ``head`` ("still", "sway", "lean") with ``sway_cm``, ``sway_hz``,
      ``lean_cm``, ``lean_s``, ``lean_at``, or ``head_path`` (a CSV of t,x,y,z);
    - the system: ``method`` ("planar", "none"), ``d2`` (m, inf or "auto"), ``head_source``
      ("oracle", "estimated", "model"), ``head_bias_cm`` (x, y, z), ``head_jitter_cm``,
      ``seed``, ``feature_width`` (m), ``require_confident_head`` (bool), ``predict``
      ("none", "constant-velocity", "kalman"), ``reproject`` (bool), ``outside`` ("black",
      "error"), ``filter``, ``display`` ("pixels", "ideal");
    - sizes and metrics: ``width``, ``height``, ``frontal_width``, ``back_width`` (pixels),
      ``spp`` (default 1), ``band``, ``hazard_bound_arcmin``, ``max_memory`` (GiB).

    Every frame renders whole driver views (as ``--frames exr``), so its metrics equal
    frames.csv's for the same options.

    ``predictor(info)`` is called once per display refresh, before its image is made, with a
    dict: ``latency_camera`` (ms), ``frame``, ``time``, ``refresh``, ``refresh_time``,
    ``capture_time``, ``head_time`` (s), ``eye_true`` (at ``time``) and
    ``eye_at_head_time`` (obstacle frame, m). It returns the eye (x, y, z, obstacle frame,
    m) the compensation uses, or None for the system's own estimate (``head_source``, then
    ``predict``). Each :class:`Step` has frames.csv's row: the times, ``eye_true``,
    ``eye_estimated``, ``eye_used``, ``head_confidence`` (and on the mesh face
    ``head_yaw_deg``, ``head_fit_margin``, ``head_yaw_true_deg``), ``d2_used``,
    ``vehicle_position``, ``vehicle_yaw_deg``, ``hazards``, with ``metrics``
    (metrics.json's content for that instant), ``truth`` and ``seethru`` (:class:`Frame`)
    and ``misregistration`` ((h, w) float32, arcmin).
    """
    return _sequence(scene, predictor, **options)


def dataset(spec, out, shard=None, exr: str = "lean", threads=None) -> dict:
    """Makes a dataset as ``seethru dataset SPEC --out OUT`` does, to the same bytes.

    ``spec``: the dataset's specification (TOML: the scene, ``samples``, ``seed``,
    ``[options]``, ``[draw]``; docs/guide/datasets.md). ``out``: its folder; samples already
    in it are kept (a killed call resumes), and it must hold the same spec's samples.
    ``shard``: ``"K/N"`` or ``(K, N)``, only the samples i with i mod N = K (so that N
    processes, Ray tasks or machines share a dataset; whichever finds every sample done writes
    the manifest). ``exr``: what each view's EXR holds ("none", "colour", "lean", "all").
    ``threads``: worker threads in [1, 1024] (default: all cores, or ``RAYON_NUM_THREADS``).

    Files are the same bytes whichever front end, shard split or thread count made them. The
    GIL is released while samples are made; Ctrl-C stops between bands of rows, keeping the
    samples already whole. A sample's warnings (a doubtful head estimate) are issued with
    :func:`warnings.warn` and listed in the result.

    Returns a dict: ``made``, ``kept`` (samples of this call's share already there),
    ``done`` and ``samples`` (of the whole dataset), ``seconds``, ``samples_per_second``
    (None when none was made), ``manifest`` (manifest.csv's :class:`pathlib.Path` once every sample
    is done, else None) and ``warnings``.
    """
    return _dataset(spec, out, shard, exr, threads)
