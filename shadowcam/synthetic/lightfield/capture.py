"""A light-field capture (paper VI, Fig. 17) with exact ground truth: screens, sweeps, HDR RAW brackets.

The :class:`~shadowcam.synthetic.lightfield.source.ReflectorSource` shines through the
mask plane onto a translucent screen at two positions; the camera films the screen
from the far side through a homography (pixel ``(row, col)`` -> screen ``(x, y)`` mm).
A camera pixel's value is the screen irradiance averaged with a bilinear footprint
(the quadrature rays' flux splatted onto the pixel grid over the pixel's screen area).
A wire of width ``1.5 * step`` sweeps the mask plane along x (``axis="x"``: a vertical
wire) or along y, ``n_frames`` frames, its centre at ``mask_start + step * t``; it
removes the flux of the rays through it (the flux is binned by mask coordinate, eight
bins per frame step), averaged over the exposure if the wire moves during it
(``shutter``). Each frame is exposed at every bracket time with
:func:`shadowcam.synthetic.sensor.simulate_raw` (noise seeded by ``[seed, screen, axis,
frame, bracket]``); the longest bracket saturates the caustic rings.

Offers
------
LightFieldCapture : the set-up (source, screens, camera, sweeps, exposures, sensor).
sweep_frames : the brackets of every frame of one sweep (a generator: memory independent of frames).
wire_cover : fraction of an exposure the moving wire covers each mask bin (a still or a moving wire).
capture_description : the ``kind: lightfield`` description (screens, sweeps, exposures, sensor).
capture_from_plan : the set-up a ``kind: lightfield`` manifest's ``synthetic`` block describes.
write_capture : DNG brackets of every frame and the description, written atomically into a directory.
"""

import dataclasses
import datetime
import json
from dataclasses import dataclass, field

import numpy as np

from shadowcam._shared.atomic import atomic_directory
from shadowcam.io.raw_writer import write_dng
from shadowcam.lightfield.render import splat_bilinear
from shadowcam.lightfield.screen import screen_coordinates
from shadowcam.synthetic.lightfield.source import ReflectorSource
from shadowcam.synthetic.sensor import SensorModel, simulate_raw

_BINS_PER_STEP = 8
#: per-axis second moment (px^2) of a camera pixel's footprint: the bilinear (tent) splat's
FOOTPRINT_VARIANCE_PX2 = 1.0 / 6.0
_WIRE_BINS = 12


@dataclass(frozen=True)
class LightFieldCapture:
    """Set-up of a synthetic light-field capture.

    Parameters
    ----------
    source : ReflectorSource
    positions_mm : tuple of float
        Screen distances from the source, nearest first.
    shape : (H, W)
        Camera pixels (even).
    n_frames : int
        Frames per sweep.
    exposure_times : tuple of float
        Bracket times, seconds.
    sensor : SensorModel
    exposure_level : float
        Fraction of the DN range the median beam pixel of the near screen reaches
        in the longest bracket.
    tilt : float
        Perspective term of the camera homographies.
    quadrature : int
        Rays per side of the flux quadrature.
    seed : int
    noise : bool
    shutter : float
        Fraction of the frame interval the longest bracket integrates over while the wire
        moves on at constant speed (each bracket over its share ``shutter * t_e / max(t)``,
        centred on the frame time); 0 (default) = the wire stands still during each
        frame's brackets (a stepped wire).
    screen_names : tuple of str, optional
        Name of each screen (default ``screen<i>``): its folder and description entry.
    """

    source: ReflectorSource = field(default_factory=ReflectorSource)
    positions_mm: tuple = (250.0, 450.0)
    shape: tuple = (96, 96)
    n_frames: int = 48
    exposure_times: tuple = (4e-3, 5e-4, 6.25e-5)
    sensor: SensorModel = field(default_factory=lambda: SensorModel(bit_depth=12, black_level=256, gain=1.0,
                                                                     read_noise=2.0))
    exposure_level: float = 0.6
    tilt: float = 2e-4
    quadrature: int = 1200
    seed: int = 0
    noise: bool = True
    shutter: float = 0.0
    screen_names: tuple = None

    def __post_init__(self):
        if not 0.0 <= self.shutter <= 1.0:
            raise ValueError(f"shutter must be in [0, 1] (fraction of the frame interval); got {self.shutter!r}")

    def screen_name(self, screen):
        """Name of screen index `screen`."""
        return self.screen_names[screen] if self.screen_names else f"screen{screen}"

    @property
    def mask_half(self):
        """Half-extent of the swept mask range, mm."""
        return self.source.aperture + 1.0

    @property
    def step(self):
        """Wire motion per frame, mm."""
        return 2 * (self.mask_half + 0.5) / self.n_frames

    @property
    def mask_start(self):
        """Wire centre at frame 0, mm."""
        return self._bin_origin + (_WIRE_BINS / 2) * self.step / _BINS_PER_STEP

    @property
    def _bin_origin(self):
        return -(self.mask_half + 0.5) - 0.25 * self.step

    def homography(self, screen):
        """Pixel ``(row, col, 1)`` -> screen ``(x, y, 1)`` of screen index `screen`."""
        z = self.positions_mm[screen]
        x, y = self.source.hits(np.array([self.mask_half]), np.array([0.0]), centre=(0, 0, z))[0]
        half = 1.1 * float(np.hypot(x, y))
        h, w = self.shape
        pitch = 2 * half / max(h, w)
        return np.array([[0.0, pitch, -pitch * (w - 1) / 2], [pitch, 0.0, -pitch * (h - 1) / 2],
                         [self.tilt * (1 + screen), 0.0, 1.0]])

    def responsivity(self):
        """Electrons per second per lux that expose the near screen at `exposure_level`."""
        lit = self.flux_bins(0, "x").sum(axis=-1)
        level = float(np.median(lit[lit > 0.05 * lit.max()]))
        span = self.sensor.white_level - self.sensor.black_level
        return self.exposure_level * span / self.sensor.gain / (max(self.exposure_times) * level)

    def flux_bins(self, screen, axis):
        """Irradiance per camera pixel split by the mask bin of its rays.

        Returns
        -------
        bins : (H, W, B) float64 ndarray
            Lux contributed by the rays of each mask bin along `axis`.
        """
        x, y, flux = self.source.quadrature(self.quadrature)
        uv = self.source.hits(x, y, centre=(0, 0, self.positions_mm[screen]))
        inverse = np.linalg.inv(self.homography(screen))
        p = np.c_[uv, np.ones(len(uv))] @ inverse.T
        rows, cols = p[:, 0] / p[:, 2], p[:, 1] / p[:, 2]
        along = x if axis == "x" else y
        n_bins = _BINS_PER_STEP * (self.n_frames + 2)
        layer = np.floor((along - self._bin_origin) / (self.step / _BINS_PER_STEP)).astype(np.int64)
        bins = splat_bilinear(rows, cols, flux, self.shape, layer=layer, n_layers=n_bins)
        _, area = screen_coordinates(self.homography(screen), self.shape)
        return bins / (area * 1e-6)[..., None]

    def screen_irradiance(self, screen):
        """Unshadowed irradiance (lux) of every camera pixel of screen index `screen`, ``(H, W)``."""
        return self.flux_bins(screen, "x").sum(axis=-1)


def sweep_frames(capture, screen, axis, *, responsivity=None, truth=None):
    """The brackets of each frame of one sweep.

    Parameters
    ----------
    capture : LightFieldCapture
    screen : int
        Screen index.
    axis : {"x", "y"}
        Mask axis the wire moves along.
    responsivity : float, optional
        Electrons per second per lux (default ``capture.responsivity()``).
    truth : dict, optional
        Filled with ``irradiance`` (H, W) and ``mask_centre`` (H, W): the flux-weighted
        mask coordinate of each pixel's rays (ground truth of the shadow position).

    Yields
    ------
    (E, H, W) uint16 ndarray
        RGGB mosaics, one per bracket.
    """
    if axis not in ("x", "y"):
        raise ValueError(f"axis must be one of 'x', 'y'; got {axis!r}")
    bins = capture.flux_bins(screen, axis)
    total = bins.sum(axis=-1)
    q = responsivity if responsivity is not None else capture.responsivity()
    if truth is not None:
        centres = capture._bin_origin + (np.arange(bins.shape[-1]) + 0.5) * capture.step / _BINS_PER_STEP
        with np.errstate(invalid="ignore", divide="ignore"):
            truth.update(irradiance=total, mask_centre=(bins @ centres) / total)
    axis_index = 0 if axis == "x" else 1
    longest = max(capture.exposure_times)
    for t in range(capture.n_frames):
        brackets = []
        for e, exposure in enumerate(capture.exposure_times):
            blur = _BINS_PER_STEP * capture.shutter * exposure / longest
            cover = wire_cover(bins.shape[-1], _BINS_PER_STEP * t, blur=blur)
            lit = np.maximum(total - bins @ cover, 0.0)
            rgb = np.repeat(lit[..., None], 3, axis=-1)
            brackets.append(simulate_raw(rgb, sensor=capture.sensor, scale=q * exposure, noise=capture.noise,
                                         seed=[capture.seed, screen, axis_index, t, e] if capture.noise else None))
        yield np.stack(brackets)


def wire_cover(n_bins, start, *, blur):
    """Fraction of an exposure during which the wire covers each mask bin.

    The wire covers bins ``[start + u, start + u + 12)`` (bin units, continuous) while its
    offset ``u`` runs uniformly over ``[-blur / 2, blur / 2]`` during the exposure.

    Parameters
    ----------
    n_bins : int
    start : float
        Wire's leading bin edge at the exposure's centre.
    blur : float, keyword-only
        Wire motion during the exposure, bins (>= 0; 0 = a still wire).

    Returns
    -------
    (n_bins,) float64 ndarray
        In [0, 1]; sums to 12 (the wire's width in bins) where the wire is inside the bins.
    """
    edges = np.arange(n_bins + 1, dtype=np.float64)

    def covered_below(x):
        # integral over the exposure of the wire's extent below mask coordinate x (bins)
        if blur <= 0:
            return np.clip(x - start, 0.0, _WIRE_BINS)
        # mean over u of clip(x - start - u, 0, W), W the wire's width: g is the antiderivative
        # of clip(y, 0, W)
        def g(y):
            return np.where(y <= 0, 0.0, np.where(y >= _WIRE_BINS, _WIRE_BINS * (y - _WIRE_BINS / 2), 0.5 * y**2))
        y = x - start
        return (g(y + blur / 2) - g(y - blur / 2)) / blur

    return np.diff(covered_below(edges))


def capture_description(capture, *, responsivity):
    """The ``kind: lightfield`` description of a capture (screens, sweeps, exposures, sensor)."""
    sensor = capture.sensor
    return {
        "kind": "lightfield",
        "screens": [{"name": capture.screen_name(i), "position_mm": float(z), "homography": capture.homography(i).tolist()}
                    for i, z in enumerate(capture.positions_mm)],
        "mask": {"position_mm": capture.source.z_mask, "start_mm": capture.mask_start, "step_mm": capture.step,
                 "n_frames": capture.n_frames},
        "exposure_times": [float(t) for t in capture.exposure_times],
        "sensor": {"black_level": sensor.black_level, "white_level": sensor.white_level, "gain": sensor.gain,
                   "read_noise": sensor.read_noise, "responsivity": float(responsivity),
                   "footprint_variance_px2": FOOTPRINT_VARIANCE_PX2},
    }


def write_capture(directory, capture, *, compression="none"):
    """Write every bracket of every frame as a DNG and ``capture.json``, atomically.

    Files are ``<screen name>/<axis>/frame<t>_b<e>.dng`` with the bracket's ``ExposureTime``.

    Returns
    -------
    dict
        The description written to ``capture.json``.
    """
    q = capture.responsivity()
    description = capture_description(capture, responsivity=q)
    start = datetime.datetime(2024, 1, 1, 12, 0, 0)
    with atomic_directory(directory) as tmp:
        for screen in range(len(capture.positions_mm)):
            for axis in ("x", "y"):
                for t, brackets in enumerate(sweep_frames(capture, screen, axis, responsivity=q)):
                    folder = tmp / capture.screen_name(screen) / axis
                    folder.mkdir(parents=True, exist_ok=True)
                    for e, (raw, exposure) in enumerate(zip(brackets, capture.exposure_times)):
                        write_dng(folder / f"frame{t:04d}_b{e}.dng", raw,
                                  bit_depth=capture.sensor.bit_depth, black_level=capture.sensor.black_level,
                                  capture_time=start + datetime.timedelta(seconds=t), exposure_time=exposure,
                                  compression=compression)
        (tmp / "capture.json").write_text(json.dumps(description, indent=1))
    return description


#: manifest ``lightfield.camera`` key -> :class:`SensorModel` field
_CAMERA_KEYS = {"gain_dn_per_e": "gain", "read_noise_dn": "read_noise"}

#: scenes of a rendered light field (manifest ``synthetic.scene``)
SCENES = {"reflector": ReflectorSource}


def capture_from_plan(plan, synthetic):
    """The :class:`LightFieldCapture` a rendered ``kind: lightfield`` manifest describes.

    Parameters
    ----------
    plan : shadowcam.io.capture_plan.CapturePlan
        Plan of the manifest (screens nearest first, bracket times).
    synthetic : mapping
        The manifest's ``synthetic`` block (``scene``, ``seed``, ``frames``, ``noise``, ``shutter``).
        The sensor's gain and read noise are the manifest's ``lightfield.camera`` keys where
        given (else the :class:`LightFieldCapture` default sensor's).
    """
    if synthetic["scene"] not in SCENES:
        raise ValueError(f"manifest {plan.manifest_path}: key 'synthetic.scene' must be one of {list(SCENES)} "
                         f"for kind lightfield; got {synthetic['scene']!r}")
    screens = plan.lightfield["screens"]
    camera = plan.lightfield["camera"]
    sensor = dataclasses.replace(LightFieldCapture().sensor, **{name: camera[key] for key, name in _CAMERA_KEYS.items()
                                                                if key in camera["given"]})
    return LightFieldCapture(source=SCENES[synthetic["scene"]](), positions_mm=tuple(s["position_mm"] for s in screens),
                             shape=tuple(plan.frame_shape), n_frames=int(synthetic["frames"]), sensor=sensor,
                             exposure_times=tuple(screens[0]["exposure_times_s"]), seed=int(synthetic["seed"]),
                             noise=bool(synthetic.get("noise", True)), shutter=float(synthetic.get("shutter", 0.0)),
                             screen_names=tuple(s["id"] for s in screens))
