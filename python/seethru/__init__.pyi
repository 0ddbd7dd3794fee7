"""Type stubs of the seethru package (the Rust extension seethru._native)."""

from os import PathLike
from typing import Any, Callable, Literal

import numpy as np
import numpy.typing as npt

__version__: str

View = Literal["truth", "occluded", "frontal", "back"]
Pose = npt.NDArray[np.float64]  # (4, 4) world_from_X, rows [R | t], last row [0, 0, 0, 1]

class Frame:
    """One rendered view, row 0 at the top; every array views the renderer's buffer (no copy).

    A render's arrays are writable; their `base` owns the buffers, which are recycled for a
    later render only when no Frame, array or view of them is left. A capture's are read-only.
    """

    view: str
    width: int
    height: int
    colour: npt.NDArray[np.float32]
    """Linear RGB radiance, (height, width, 3) float32; 1.0 is the PNG's white."""
    white_cd_m2: float | None
    """In a scene lit in physical units (`[sun] illuminance_lux`), the luminance of a colour
    of 1.0, cd/m²: `colour * white_cd_m2` is what its EXR holds. None in relative units."""
    depth: npt.NDArray[np.float32]
    """Distance along the pixel-centre ray, metres, +inf for sky; (height, width) float32."""
    camera_z: npt.NDArray[np.float32]
    """Depth along the camera's viewing axis, metres, +inf for sky; (height, width) float32."""
    position: npt.NDArray[np.float32]
    """World position of the visible point, metres, NaN for sky; (height, width, 3) float32."""
    normal: npt.NDArray[np.float32]
    """Unit world normal facing the camera (sky: back along the ray); (height, width, 3)."""
    object_id: npt.NDArray[np.uint32]
    """Object index in the scene + 1 (obstacle last), 0 for sky; (height, width) uint32."""
    part_id: npt.NDArray[np.uint32]
    """Part of the object (box face, cap, mesh group), 0 for sky; (height, width) uint32."""
    row_times: npt.NDArray[np.float64] | None
    """Each row's exposure as (start, end), seconds after the frame's instant (its last row
    read out), (height, 2) float64, from the camera's shutter keys: zeros for a global
    shutter with an instant exposure and for the driver's views; None for a frame read from a
    file and for the display's image."""
    _buffer_addresses: dict[str, int]

class Scene:
    """A scene file read and validated as by the command line."""

    @staticmethod
    def load(path: str | PathLike[str]) -> Scene:
        """Reads a scene (TOML). ValueError: a bad key or value; OSError: unreadable file."""
    def copy(self) -> Scene:
        """An independent copy sharing the built world while the geometry is the same."""
    @property
    def path(self) -> str: ...
    @property
    def warnings(self) -> list[str]:
        """What reading the scene doubted, a line each (an OpenDRIVE map's dropped parts)."""
    eye: tuple[float, float, float]
    """The driver's eye, world metres; setting it moves the driver camera (same orientation)."""
    driver_pose: Pose
    """world_from_camera of the driver camera (it looks down -z)."""
    frontal_pose: Pose
    """world_from_camera of the frontal camera (the compensation keeps [calibration])."""
    back_pose: Pose
    """world_from_camera of the back camera (the compensation keeps [calibration])."""
    obstacle_pose: Pose
    """world_from_obstacle: display centre at the origin, driver on +z; cameras don't follow."""
    display_size: tuple[float, float]
    """Display (width, height), metres, each in [1e-6, 100]."""
    def resolution(self, view: View) -> tuple[int, int]:
        """The (width, height) a view renders at without overrides."""
    def render(
        self,
        view: View,
        # The option table's (render): tests/option_table.rs checks it (SEETHRU_BLESS=1 rewrites it).
        width: int | None = None,
        height: int | None = None,
        spp: int = 4,
        max_memory: float = 8.0,
        # End of the option table's.
        out: Frame | None = None,
    ) -> Frame:
        """Renders a view as `seethru render` does (GIL released; Ctrl-C stops it).

        Without `out`, into a new Frame (its buffers recycled from frames no longer
        referenced, see `frame_pool`). With `out`, into that Frame's own arrays, in place, and
        returns it: views of its arrays see the new render. ValueError if `out` is of another
        view or size, is a capture's (read-only) frame, has an array whose
        `flags.writeable` is False, or is being rendered into (or read by a seethru call) in
        another thread. An interrupted render leaves `out` partly rewritten.
        """

class Run:
    """One run of the see-through system."""

    frames: dict[str, Frame]
    """truth, occluded, frontal, back, display, seethru."""
    metrics: dict[str, Any]
    """metrics.json's content."""
    report: dict[str, Any]
    """run.json's content."""
    hazards: dict[str, Any]
    """hazards.json's content (a score's at the default bound, 30 arcmin)."""
    misregistration: npt.NDArray[np.float32]
    """Arcmin per driver-view pixel, NaN outside the display and on blank pixels; (h, w)."""
    missing: npt.NDArray[np.bool_]
    """Display pixels whose truth point the frontal camera cannot see; (h, w) bool."""

def run(
    scene: Scene,
    *,
    # The option table's (run): tests/option_table.rs checks it (SEETHRU_BLESS=1 rewrites it).
    method: Literal["none", "planar", "ground", "plane-fit", "depth"] = "planar",
    d2: float | str = "inf",
    head: Literal["oracle", "estimated", "model"] = "oracle",
    head_bias_cm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    head_jitter_cm: float = 0.0,
    seed: int = 1,
    feature_width: float = 0.064,
    require_confident_head: bool = False,
    min_head_confidence: float = 0.5,
    speed: float = 0.0,
    yaw_rate: float = 0.0,
    latency_camera: float = 0.0,
    outside: Literal["error", "black"] = "error",
    filter: Literal["bilinear", "bicubic"] = "bilinear",
    display: Literal["pixels", "ideal"] = "pixels",
    frontal_width: int | None = None,
    back_width: int | None = None,
    eyes: Literal["mono", "left", "right"] = "mono",
    ipd: float = 0.064,
    target_eye: Literal["cyclopean", "left", "right"] = "cyclopean",
    band: int = 5,
    hazard_bound_arcmin: float = 30.0,
    depth_sensor: Literal["ideal", "tof", "stereo"] = "ideal",
    depth_resolution: int | None = None,
    depth_range: float | None = None,
    depth_noise: float | None = None,
    depth_quantum: float | None = None,
    fill: Literal["none", "background", "inpaint"] = "none",
    width: int | None = None,
    height: int | None = None,
    spp: int = 4,
    max_memory: float = 8.0,
    # End of the option table's.
) -> Run:
    """Runs the see-through system as `seethru run` does, returning instead of writing."""

def options() -> list[dict[str, Any]]:
    """The option table of run, capture and compare, and of what sequence shares with them
    (the flags of the commands of the same names): name, flag, kind, min, max, choices, unit,
    default, default_derived, command_defaults (a command's own default where it differs:
    {"sequence": 1} for spp), help, read_with and commands per option, in `seethru run
    --help`'s order."""

def spec(command: Literal["run", "capture", "compare", "sequence", "render"], **options: Any) -> dict[str, Any]:
    """The run specification `command` would make of `options`, every option checked and
    nothing rendered ({"command", "options": {name: value}}), as `seethru spec` prints it."""

def read_frame(path: str | PathLike[str]) -> Frame:
    """Reads an EXR written by `seethru render`/`run` as a Frame."""

def frame_pool(clear: bool = False) -> dict[str, int]:
    """The freed frame buffers kept for reuse by `Scene.render`: `frames`, `bytes`, and the
    bounds `max_frames`, `max_bytes` (oldest freed first). `clear=True` frees them first."""

def compare(
    scene: Scene,
    methods: list[str] | None = None,
    *,
    # The option table's (compare): tests/option_table.rs checks it (SEETHRU_BLESS=1 rewrites it).
    head: Literal["oracle", "estimated", "model"] = "oracle",
    seed: int = 1,
    speed: float = 0.0,
    yaw_rate: float = 0.0,
    latency_camera: float = 0.0,
    frontal_width: int | None = None,
    back_width: int | None = None,
    band: int = 5,
    hazard_bound_arcmin: float = 30.0,
    depth_sensor: Literal["ideal", "tof", "stereo"] = "ideal",
    depth_resolution: int | None = None,
    depth_range: float | None = None,
    depth_noise: float | None = None,
    depth_quantum: float | None = None,
    fill: Literal["none", "background", "inpaint"] = "none",
    width: int | None = None,
    height: int | None = None,
    spp: int = 4,
    max_memory: float = 8.0,
    # End of the option table's.
) -> dict[str, Any]:
    """`seethru compare`: {"rows": compare.json's rows, "strips": {method: (h, w, 3) uint8}}.

    methods: none, planar-inf, planar-auto, plane-fit, ground, depth-ideal, depth-tof,
    depth-stereo (default: compare's six). Each option is refused where no listed method reads
    it (as on the command line). A method the scene does not admit
    (ground without a road) has a row whose "reason" says why, and no strip.
    """

def ratio(setup: Literal["occlusion", "foreshortening"], **options: Any) -> dict[str, Any]:
    """`seethru ratio SETUP ... --json`: L (occlusion) or l and gamma (degrees,
    foreshortening), b1, d2, d1, bh (required), model_d2, head_bias_cm, width (1280)."""

def analyze(**options: float) -> dict[str, Any]:
    """`seethru analyze --json` whole (claims, evaluation, lens_and_eyes, error_budget_das):
    d1, d2, bh, width, height, theta_f, frontal_px, L, b1, l, gamma, tolerance, k1, ipd."""

class Capture:
    """What a see-through system's algorithm receives (`seethru capture`), in memory."""

    frontal: Frame
    """Read-only views of the capture's buffers (no copy): `score` reads the same pixels."""
    back: Frame
    """Read-only views, as frontal."""
    inverse_depth: npt.NDArray[np.float32] | None
    """The depth sensor's inverse depth, 1/m (0: no return); with depth=True only; read-only."""
    head: dict[str, Any]
    """The head tracker's output: source, eye_world_m, eye_obstacle_m, detection."""
    calibration: dict[str, Any]
    """calibration.json's content (OpenCV's conventions)."""
    fingerprint: str
    display_resolution: tuple[int, int]
    """(width, height) display pixels: a map is (height, width, 2)."""
    def save(self, path: str | PathLike[str], exr: Literal["all", "lean", "colour", "none"] = "all") -> None:
        """Writes the folder `seethru capture --exr EXR` writes, which `seethru score` reads;
        refused for a scene changed in memory (the folder names its scene file)."""

def capture(
    scene: Scene,
    depth: bool = False,
    *,
    # The option table's (capture): tests/option_table.rs checks it (SEETHRU_BLESS=1 rewrites it).
    head: Literal["oracle", "estimated", "model"] = "oracle",
    head_bias_cm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    head_jitter_cm: float = 0.0,
    seed: int = 1,
    feature_width: float = 0.064,
    require_confident_head: bool = False,
    min_head_confidence: float = 0.5,
    speed: float = 0.0,
    yaw_rate: float = 0.0,
    latency_camera: float = 0.0,
    frontal_width: int | None = None,
    back_width: int | None = None,
    eyes: Literal["mono", "left", "right"] = "mono",
    ipd: float = 0.064,
    target_eye: Literal["cyclopean", "left", "right"] = "cyclopean",
    depth_sensor: Literal["ideal", "tof", "stereo"] = "ideal",
    depth_resolution: int | None = None,
    depth_range: float | None = None,
    depth_noise: float | None = None,
    depth_quantum: float | None = None,
    width: int | None = None,
    height: int | None = None,
    spp: int = 4,
    max_memory: float = 8.0,
    # End of the option table's.
) -> Capture:
    """`seethru capture` in memory, with its flags as keywords (depth_* with depth=True)."""

def load_capture(path: str | PathLike[str]) -> Capture:
    """A folder written by `seethru capture` or `Capture.save`, captured again from its
    `truth/capture_spec.json` and checked against its fingerprint, as `seethru score` reads it."""

def score(
    capture: Capture,
    map: npt.ArrayLike | None = None,
    display_image: npt.ArrayLike | None = None,
    filter: str = "bilinear",
    band: int = 5,
    display_codes: bool = False,
) -> Run:
    """`seethru score`: a method's display map (h, w, 2) and/or image (h, w, 3) measured."""

def dataset(
    spec: str | PathLike[str],
    out: str | PathLike[str],
    shard: str | tuple[int, int] | None = None,
    exr: Literal["none", "colour", "lean", "all"] = "lean",
    threads: int | None = None,
) -> dict[str, Any]:
    """`seethru dataset SPEC --out OUT [--shard K/N]`: the same files; what it did as a dict
    (made, kept, done, samples, seconds, samples_per_second, manifest, warnings)."""

class Step:
    """One displayed frame of a :class:`Sequence` (a row of frames.csv, and its views)."""
    latency_camera: float  # ms, of this frame's sequence
    frame: int  # from 0 in its latency's sequence
    time: float  # s, when the frame is looked at
    refresh: int
    refresh_time: float  # s
    capture_time: float  # s
    head_time: float  # s
    eye_true: tuple[float, float, float]  # obstacle frame, m, at `time`
    eye_estimated: tuple[float, float, float]  # the system's head estimate, m
    eye_used: tuple[float, float, float]  # what the compensation used, m
    head_confidence: float | None  # [0, 1], image-based head estimates only
    head_yaw_deg: float | None  # the mesh face's fitted yaw from facing the back camera, degrees
    head_fit_margin: float | None  # the yaw fit's margin, [0, 0.05] (mesh face only)
    head_yaw_true_deg: float | None  # the mesh face's true yaw from facing the back camera
    d2_used: float | None  # m, the working distance chosen with d2="auto"
    vehicle_position: tuple[float, float, float]  # the pivot, world, m
    vehicle_yaw_deg: float
    metrics: dict[str, Any]  # metrics.json's content for this instant
    hazards: list[dict[str, Any]]  # every hazard object's visibility, scene order
    truth: Frame
    seethru: Frame
    misregistration: npt.NDArray[np.float32]  # (height, width), arcmin, NaN off the display

class Sequence:
    """A sequence being stepped through: iterate it for its :class:`Step`s."""
    def __iter__(self) -> Sequence: ...
    def __next__(self) -> Step: ...
    def __len__(self) -> int:
        """Frames in all, over every camera latency."""

def sequence(
    scene: Scene,
    predictor: Callable[[dict[str, Any]], tuple[float, float, float] | None] | None = None,
    *,
    duration: float = 4.0,
    fps: float = 60.0,
    display_hz: float | None = None,
    speed: float = 0.0,
    yaw_rate: float = 0.0,
    head: Literal["still", "sway", "lean"] = "still",
    head_path: str | PathLike[str] | None = None,
    sway_cm: float = 3.0,
    sway_hz: float = 0.5,
    lean_cm: float = 10.0,
    lean_s: float = 0.3,
    lean_at: float = 0.5,
    latency_camera: float | list[float] = 0.0,
    latency_tracking: float = 0.0,
    predict: Literal["none", "constant-velocity", "kalman"] = "none",
    reproject: bool = False,
    head_source: Literal["oracle", "estimated", "model"] = "oracle",
    flip: bool = False,
    # The option table's (sequence): tests/option_table.rs checks it (SEETHRU_BLESS=1 rewrites it).
    method: Literal["none", "planar", "ground", "plane-fit", "depth"] = "planar",
    d2: float | str = "inf",
    head_bias_cm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    head_jitter_cm: float = 0.0,
    seed: int = 1,
    feature_width: float = 0.064,
    require_confident_head: bool = False,
    min_head_confidence: float = 0.5,
    speed: float = 0.0,
    yaw_rate: float = 0.0,
    outside: Literal["error", "black"] = "black",
    filter: Literal["bilinear", "bicubic"] = "bilinear",
    display: Literal["pixels", "ideal"] = "pixels",
    frontal_width: int | None = None,
    back_width: int | None = None,
    band: int = 5,
    hazard_bound_arcmin: float = 30.0,
    width: int = 640,
    height: int | None = None,
    spp: int = 1,
    max_memory: float = 8.0,
    # End of the option table's.
) -> Sequence:
    """`seethru sequence` as an iterator of measured frames, the command's loop options as
    keywords (refused as it refuses them); `predictor(info)` supplies the eye per refresh."""
