"""First streaming pass over an outdoor time-lapse: registration, gains, levels.

Frames arrive one at a time in time order; the first is the reference. For
each frame: estimate its lit gain on pixels lit in the reference (shift-insensitive
median), mask the pixels the shadow reached, estimate the sub-pixel shift to
the reference (:mod:`shadowcam.outdoor.registration`), resample, then estimate the lit
and sky gains again on the aligned frame (:mod:`shadowcam.outdoor.photometric`) and
update the per-pixel shadow level (running minimum of the 3-frame smoothed
sky-normalised luminance). State is a few ``(H, W)`` arrays whatever the
number of frames.

Time parts (one job each): given frame 0, each frame's shift and gains depend
on the previous frame only through the starting point of their searches (the
gain prior, the shift's initial value, the lit-to-sky gain ratio where the lit
gain is searched for; that ratio is also the lit gain's fallback under a cloud
that covers every lit pixel), and the per-pixel minimum merges exactly. A part
``start:stop`` therefore first runs over ``overlap`` warm-up frames before
`start` (searches started from the exposure metadata, zero shift and the
brightest lit pixels; the 3-frame windows need two frames before `start`) and records
``start .. stop - 1``; :func:`merge_parts` concatenates and takes the minimum.
The parts equal the single job where the searches converge to the same
solution from both starting points (measured on dev_ridge: see
``tests/test_outdoor_normalise.py``).

Offers
------
SequenceNormaliser : the streaming pass; :meth:`update` per frame, :meth:`result` (or :meth:`partial`).
normalise_frames : run it over an iterable of frames (one job).
normalise_part : run it over one time part (with warm-up frames before it).
part_frames : the frames a time part reads.
merge_parts : merge the parts' results (concatenation and per-pixel minimum).
PartMerger : the same, one part at a time (memory independent of the number of parts).
aligned_luminance : one frame's registered luminance from the pass's results.
GAIN_SOURCES : where a frame's lit gain comes from (the pass's ``gain_source`` codes).
cloud_shade : the sun term's transmittance under a cloud over every lit pixel, per frame.
cloud_shades : that and the shade field over the frame, per frame (what the merge records).
clouded_reference_gains : the lit gains of the first frames when the reference's lit pixels were under a cloud.

Each frame also gives its blocks' lit level (:func:`shadowcam.outdoor.shade_field.block_levels`);
the merge turns them into the cloud's shade field over the frame (``shade_field``).
"""

import numpy as np

from shadowcam._shared.validation import check_array, check_same_shape
from shadowcam.outdoor.clipping import clipped_lit_levels, clipped_samples
from shadowcam.outdoor.frame_kernels import normalise_smooth_minimum
from shadowcam.outdoor.photometric import estimate_gain, estimate_lit_gain, lit_at_start, luminance
from shadowcam.outdoor.registration import (block_all, block_mean, pyramid_levels, reference_levels,
                                    registration_factor, shift_coarse_to_fine, soft_shadow, static_weight)
from shadowcam.outdoor.shade_field import block_grid, block_levels, shade_field, unclouded_blocks
from shadowcam.outdoor.sky_mask import auto_sky_mask
from shadowcam.outdoor.translation import translate, translate_with_block_means

#: contrast (shadow / lit level) below which a pixel counts as having been shadowed
SHADOWED_CONTRAST = 0.3
#: a first frame whose lit-to-sky gain ratio is below this fraction of a later frame's was under a
#: cloud over the reference's lit pixels (:func:`clouded_reference_gains`)
CLOUDED_REFERENCE = 0.8
#: per-frame results of the pass, concatenated over time parts
_CURVES = ("shift", "gain_lit", "gain_sky", "kept_lit", "gain_source", "gain_median", "shade_levels")
#: ``gain_source`` codes: where a frame's lit gain comes from
GAIN_SOURCES = {0: "unclouded lit pixels", 1: "sky gain x lit-to-sky ratio of the frame before "
                "(for a clouded reference: of the frames after)",
                2: "median of the lit pixels (no sky-lit pixels)"}


class SequenceNormaliser:
    """Streaming registration and photometric normalisation.

    Parameters
    ----------
    sky : (H, W) bool ndarray, optional
        Sky mask (manifest override); default: :func:`shadowcam.outdoor.sky_mask.auto_sky_mask`
        of the first frame.
    exposure_gain : (T,) ndarray, optional
        Gains from exposure metadata (NaN where unknown); seed the gain search.
    sky_params : dict, optional
        Options of :func:`shadowcam.outdoor.sky_mask.auto_sky_mask`.
    registration_size : int, optional
        Shifts and gains are estimated on frames reduced by an integer factor
        (:func:`shadowcam.outdoor.registration.block_mean`) to at most this many pixels
        on the longer side; the shift is scaled back and the per-pixel levels
        stay at full resolution. Frames this small or smaller are not reduced.
    registration_levels : int, optional
        Coarser levels (factor 2 each) of the coarse-to-fine registration on the
        reduced frames (:func:`shadowcam.outdoor.registration.shift_coarse_to_fine`): a
        shake of up to about ``4 * 2**levels`` reduced pixels from the previous
        frame's is recovered; fewer levels on small frames.
    registration_margin : int, optional
        Pixels of the reduced frames left out around the moving shadow edge
        (:func:`shadowcam.outdoor.registration.static_weight` ``margin``) beyond the
        shadow's soft edge and beyond the reference's edge with a soft edge on either side,
        whose width (penumbra, optics blur, upsampling) is measured in each frame
        (:func:`shadowcam.outdoor.registration.soft_shadow`): the band-pass response of a
        moved edge reaches about twice its outer scale (6) beyond it.
    shade_block : int, optional
        Side of the cloud shade field's blocks in frame pixels
        (:mod:`shadowcam.outdoor.shade_field`; on the reduced frames, rounded): several times the
        ridge penumbra's width, so that what is left of it stays a minority of a block, and well
        below a cloud's scale.
    reference : (H, W, C) ndarray, optional
        The first frame of the time-lapse, required when `first_index` > 0
        (a time part: the frames fed start later).
    first_index : int, optional
        Index of the first frame fed to :meth:`update`. 0: it is the reference.
        Otherwise the search for the first frame fed starts from the exposure
        metadata (or gain 1) and zero shift, and converges over the frames
        before `record_from` (the warm-up).
    record_from : int, optional
        Frames before this index are processed (warm-up) but not recorded,
        and the running minimum uses the 3-frame windows ending at this frame
        or later; ``record_from - first_index`` must be >= 2 when ``first_index > 0``.
    white_level : float or None, optional
        Decoded value of the sensor's white level (:func:`shadowcam.outdoor.clipping.store_white_level`):
        the reference's lit pixels clipped in any channel give no gain or block level, and their lit
        level comes from their neighbours' lit-to-shadow ratio
        (:func:`shadowcam.outdoor.clipping.clipped_lit_levels`). None: nothing is known to clip.
    """

    def __init__(self, *, sky=None, exposure_gain=None, sky_params=None, registration_size=1536,
                 registration_levels=2, registration_margin=6, shade_block=96, reference=None, first_index=0,
                 record_from=0, white_level=None):
        self.white_level = None if white_level is None else float(white_level)
        self._sky = None if sky is None else np.asarray(sky, dtype=bool)
        self._exposure = None if exposure_gain is None else np.asarray(exposure_gain, dtype=np.float64)
        self._sky_params = dict(sky_params or {})
        self._registration_size = int(registration_size)
        registration_factor((1, 1), max_size=self._registration_size)  # validates the option
        self._registration_levels = int(registration_levels)
        self._registration_margin = int(registration_margin)
        if self._registration_margin < 1:
            raise ValueError(f"registration_margin must be >= 1 pixel; got {registration_margin}")
        pyramid_levels((1, 1), levels=self._registration_levels)  # validates the option
        self._shade_block = int(shade_block)
        if self._shade_block < 1:
            raise ValueError(f"shade_block must be >= 1 pixel; got {shade_block}")
        self._k, self.record_from = int(first_index), int(record_from)
        if self._k < 0 or (self._k > 0 and self.record_from - self._k < 2) or self.record_from < self._k:
            raise ValueError(f"first_index {first_index} and record_from {record_from}: need "
                             "0 <= first_index <= record_from - 2 (two warm-up frames), or both 0")
        self.shifts, self.gain_lit, self.gain_sky, self.kept_lit, self.gain_source = [], [], [], [], []
        self.gain_median = []  # median ratio of every lit pixel: follows a cloud (its shade, see result)
        self.shade_levels = []  # (By, Bx) per frame: the blocks' lit level (the cloud's shade field)
        self._recent = []
        self._last = None  # (shift, gain_lit, gain_sky) of the previous frame processed
        self._lit_to_sky = 1.0  # gain_lit / gain_sky of the previous frame (None: not known yet)
        if self._k > 0:
            if reference is None:
                raise ValueError("reference (the first frame) is required when first_index > 0")
            self._start(np.asarray(reference, dtype=np.float32))
            seed = self._exposure[self._k - 1] if self._exposure is not None and self._k - 1 < self._exposure.size \
                else np.nan
            seed = float(seed) if np.isfinite(seed) else 1.0
            self._last = (np.zeros(2), seed, seed)
            self._lit_to_sky = None

    def _start(self, frame):
        check_array(frame, "frame", ndim=3)
        height, width = frame.shape[:2]
        if self._sky is None:
            self._sky = auto_sky_mask(frame, **self._sky_params)
        elif self._sky.shape != (height, width):
            raise ValueError(f"sky mask {self._sky.shape} does not match the frames ({height}, {width})")
        self.reference = frame.astype(np.float32)
        self.reference_luma = luminance(frame)
        self.lit_at_start, _ = lit_at_start(self.reference_luma, valid=~self._sky)
        self.shadowed_at_start = ~self._sky & ~self.lit_at_start
        self._shadow_min = np.full((height, width), np.inf, dtype=np.float32)
        # working size of registration and gains: masks hold where the whole block does
        self.factor = registration_factor((height, width), max_size=self._registration_size)
        self._small_reference = block_mean(self.reference_luma, self.factor)
        # the reference's band-pass and gradients at every registration level: once, not per frame
        self._reference_levels = reference_levels(
            self._small_reference, levels=pyramid_levels(self._small_reference.shape, levels=self._registration_levels))
        self._small_lit = block_all(self.lit_at_start, self.factor)
        # the lit pixels whose reading is their level: a clipped one's is a lower bound of its light
        self._small_measured = block_all(self.lit_at_start & ~self._clipped(frame), self.factor)
        self._small_valid = block_all(~self._sky, self.factor)
        self._small_shadowed = block_all(self.shadowed_at_start, self.factor)
        self._row_edges, self._col_edges, self.shade_rows, self.shade_cols = block_grid(
            self._small_reference.shape, block=max(1, round(self._shade_block / self.factor)), factor=self.factor)

    def _clipped(self, frame):
        if self.white_level is None:
            return np.zeros(frame.shape[:2], dtype=bool)
        return clipped_samples(frame, white_level=self.white_level)

    def _penumbra_reach(self, small, rough):
        """Reduced pixels the ridge's penumbra may reach beyond its core and beyond the ground shadowed
        from the start: twice the soft edge's width measured in this frame
        (:func:`shadowcam.outdoor.registration.soft_shadow`, as its registration weights take it), 0
        before the shadow has a core."""
        _, width = soft_shadow(small, self._small_reference, lit_reference=self._small_lit, gain=rough,
                               valid=self._small_valid)
        return int(np.ceil(2 * width)) if np.isfinite(width) else 0

    def _prior(self, previous, k):
        if self._exposure is not None and k < self._exposure.size and np.isfinite(self._exposure[k]):
            return float(self._exposure[k]) * (previous / self._exposure[k - 1]
                                              if np.isfinite(self._exposure[k - 1]) else 1.0)
        return previous

    def _gains(self, small, rough, last_gain, last_sky, levels):
        """Sky gain, then the lit gain where the sky gain and the lit-to-sky ratio put it
        (:func:`shadowcam.outdoor.photometric.estimate_lit_gain`) on the lit pixels of the
        blocks no cloud clearly dims (:func:`shadowcam.outdoor.shade_field.unclouded_blocks`
        of the blocks' `levels`); see :data:`GAIN_SOURCES`."""
        ref = self._small_reference
        if not self._small_shadowed.any():
            gain_lit, kept = estimate_gain(small, ref, pixels=self._small_measured, prior=rough)
            return gain_lit, gain_lit, kept, 2
        gain_sky, _ = estimate_gain(small, ref, pixels=self._small_shadowed, prior=last_sky * rough / last_gain)
        expected = None if self._lit_to_sky is None else gain_sky * self._lit_to_sky
        unclouded = unclouded_blocks(levels)
        if unclouded.any() and not unclouded[np.isfinite(levels)].all():  # part of the frame under a cloud
            # no cloud brightens a block: the brightest block's level is the unclouded one, where
            # the unclouded blocks hold a population at or above the expected level
            blocks = np.repeat(np.repeat(unclouded, np.diff(self._row_edges), axis=0), np.diff(self._col_edges), axis=1)
            _, kept, found = estimate_lit_gain(small, ref, pixels=self._small_measured & blocks, expected=expected)
            if found:
                gain_lit = float(np.nanmax(levels))
                self._lit_to_sky = gain_lit / gain_sky
                return gain_lit, gain_sky, kept, 0
        gain_lit, kept, found = estimate_lit_gain(small, ref, pixels=self._small_measured, expected=expected)
        if not np.isfinite(gain_lit):  # too few lit pixels and no ratio yet
            gain_lit, kept = estimate_gain(small, ref, pixels=self._small_measured, prior=rough)
            return gain_lit, gain_sky, kept, 2
        self._lit_to_sky = gain_lit / gain_sky
        return gain_lit, gain_sky, kept, 0 if found else 1

    def update(self, frame):
        """Process the next frame.

        Parameters
        ----------
        frame : (H, W, C) or (H, W) ndarray
            The frame in colour, or (after frame 0, which sets the reference and
            its sky mask from colour) its luminance
            (:func:`shadowcam.outdoor.photometric.luminance`): the pass uses
            nothing else of the later frames, so a reader that gives the
            luminance directly (:func:`shadowcam.io.frame_store.iter_store_luminance`)
            saves the colour image.
        """
        frame = np.asarray(frame, dtype=np.float32)
        k = self._k
        check_array(frame, "frame", ndim=3 if k == 0 else (2, 3))
        if k == 0:
            self._start(frame)
            shift, gain_lit, gain_sky, luma = np.zeros(2), 1.0, 1.0, self.reference_luma
            kept, source, rough = int(self._small_measured.sum()), 0, 1.0
            levels = block_levels(self._small_reference, self._small_reference, pixels=self._small_measured,
                                  row_edges=self._row_edges, col_edges=self._col_edges,
                                  reached_below=SHADOWED_CONTRAST)
        else:
            if frame.shape[:2] != self.reference.shape[:2] or frame.shape[2:] not in ((), self.reference.shape[2:]):
                raise ValueError(f"frame {k} has shape {frame.shape}, the first frame {self.reference.shape}")
            last_shift, last_gain, last_sky = self._last
            raw = luminance(frame) if frame.ndim == 3 else frame
            factor, ref = self.factor, self._small_reference
            small = block_mean(raw, factor)
            rough, _ = estimate_gain(small, ref, pixels=self._small_measured, prior=self._prior(last_gain, k))
            weight = static_weight(small, ref, lit_reference=self._small_lit, gain=rough, valid=self._small_valid,
                                   margin=self._registration_margin)
            shift, _ = shift_coarse_to_fine(small, ref, weight=weight, initial=last_shift / factor,
                                            levels=self._registration_levels, prepared=self._reference_levels)
            shift = shift * factor
            # the oldest of the three frames kept is released by this frame's window: its buffer is reused
            spare = self._recent.pop(0) if len(self._recent) == 3 else None
            luma, small = translate_with_block_means(raw, shift, factor=factor, out=spare)
            del raw
            levels = block_levels(small, ref, pixels=self._small_measured, row_edges=self._row_edges,
                                  col_edges=self._col_edges, reached_below=SHADOWED_CONTRAST * rough,
                                  dark=self._small_valid & ~self._small_lit, reach=self._penumbra_reach(small, rough))
            gain_lit, gain_sky, kept, source = self._gains(small, rough, last_gain, last_sky, levels)
        self._last = (np.asarray(shift, dtype=np.float64), float(gain_lit), float(gain_sky))
        if k >= self.record_from:
            self.shifts.append(self._last[0])
            self.gain_lit.append(self._last[1])
            self.gain_sky.append(self._last[2])
            self.kept_lit.append(int(kept))
            self.gain_source.append(int(source))
            self.gain_median.append(float(rough))
            self.shade_levels.append(levels.astype(np.float32))
        if luma is self.reference_luma:
            luma = luma.copy()
        window = self._recent[-2:] if len(self._recent) >= 2 and k >= self.record_from else (None, None)
        # luma /= gain_sky in place, then the minimum of 0.25 a + 0.5 b + 0.25 c (float32, in that order)
        normalise_smooth_minimum(luma, np.float32(gain_sky), window[0], window[1], self._shadow_min)
        self._recent = (self._recent + [luma])[-3:]
        self._k += 1

    def partial(self):
        """Return the recorded frames' results, to merge with :func:`merge_parts`.

        Returns
        -------
        dict
            ``first_frame`` (index of the first recorded frame), ``shift (T_part, 2)``,
            ``gain_lit``, ``gain_sky``, ``kept_lit``, ``gain_source (T_part,)`` (:data:`GAIN_SOURCES`),
            ``shade_levels (T_part, By, Bx)`` with ``shade_rows (By,)``, ``shade_cols (Bx,)``,
            ``shadow_min (H, W)``
            (running minimum over the part's 3-frame windows), ``sky``, ``lit_at_start``
            ``(H, W)``, ``reference (H, W, C)`` (frame 0; the same in every part) and ``white_level``
            (NaN: none known).
        """
        if not self.shifts:
            raise ValueError("no frames were recorded (feed frames up to and past record_from)")
        return {
            "first_frame": self.record_from,
            "shift": np.array(self.shifts),
            "gain_lit": np.array(self.gain_lit),
            "gain_sky": np.array(self.gain_sky),
            "kept_lit": np.array(self.kept_lit),
            "gain_source": np.array(self.gain_source, dtype=np.int8),
            "gain_median": np.array(self.gain_median),
            "shade_levels": np.array(self.shade_levels),
            "shade_rows": self.shade_rows,
            "shade_cols": self.shade_cols,
            "shadow_min": self._shadow_min,
            "sky": self._sky,
            "lit_at_start": self.lit_at_start,
            "reference": self.reference,
            "white_level": np.nan if self.white_level is None else self.white_level,
        }

    def result(self):
        """Return the pass's results (a dict of arrays; see :func:`normalise_frames`)."""
        return merge_parts([self.partial()])


class PartMerger:
    """Merge the time parts of the first pass one at a time (exactly: concatenation and minimum).

    State: the per-frame curves, the running per-pixel minimum and frame 0's
    arrays (a few ``(H, W)`` arrays), whatever the number of parts; a part can be
    released once added.
    """

    def __init__(self):
        self._curves = {key: [] for key in _CURVES}
        self._shadow_min = self._sky = self._lit = self._reference = None
        self._white_level = np.nan
        self._next = 0

    def add(self, part):
        """Add the next part (:meth:`SequenceNormaliser.partial`; parts in time order from frame 0)."""
        if part["first_frame"] != self._next:
            raise ValueError(f"parts must cover consecutive frames from 0; a part starts at frame "
                             f"{part['first_frame']}, expected {self._next}")
        self._next += len(part["gain_lit"])
        for key in _CURVES:
            self._curves[key].append(np.asarray(part[key]))
        if self._shadow_min is None:
            self._shadow_min = np.array(part["shadow_min"], dtype=np.float32)
            self._sky, self._lit = np.asarray(part["sky"], dtype=bool), np.asarray(part["lit_at_start"], dtype=bool)
        else:
            np.minimum(self._shadow_min, part["shadow_min"], out=self._shadow_min)
        if self._reference is None and part.get("reference") is not None:
            self._reference = part["reference"]
            self._white_level = float(part.get("white_level", np.nan))
        self._grid = (np.asarray(part["shade_rows"]), np.asarray(part["shade_cols"]))

    def result(self):
        """Return the merged result (a dict; see :func:`normalise_frames`)."""
        if self._shadow_min is None:
            raise ValueError("parts must hold at least one part")
        if self._next < 3:
            raise ValueError(f"an outdoor time-lapse needs at least 3 frames; got {self._next}")
        if self._reference is None:
            raise ValueError("no part holds the reference frame (frame 0)")
        sky, lit, shadow_min = self._sky, self._lit, self._shadow_min
        ref = luminance(self._reference)
        curves = {key: np.concatenate(values) for key, values in self._curves.items()}
        curves["gain_lit"], curves["gain_source"] = clouded_reference_gains(
            curves["gain_lit"], curves["gain_sky"], curves["gain_source"])
        # sky-normalised levels -> the reference's lit scale (1 unless the reference was under a cloud)
        to_lit = np.float32(curves["gain_sky"][0] / curves["gain_lit"][0])
        with np.errstate(divide="ignore", invalid="ignore"):
            contrast = np.where(ref > 0, shadow_min * to_lit / ref, np.inf)
        shadowed = lit & (contrast < SHADOWED_CONTRAST)
        clipped = lit & (clipped_samples(self._reference, white_level=self._white_level)  # a lower bound of the light
                         if np.isfinite(self._white_level) else False)
        measured = shadowed & ~clipped
        ratio = float(np.median(contrast[measured])) if measured.any() else 0.1
        shadow_level = np.where(shadowed | (~sky & ~lit), shadow_min, ratio * ref / to_lit)
        lit_level = np.where(lit, ref, shadow_min * to_lit / ratio)
        lit_level = clipped_lit_levels(lit_level, shadow_min * to_lit, clipped=clipped & shadowed, trusted=shadowed,
                                       fallback_ratio=1.0 / ratio)
        shade, field = cloud_shades(curves["gain_median"], curves["gain_lit"], curves["gain_source"],
                                    curves["shade_levels"], shadow_ratio=ratio)
        return {
            **curves,
            "cloud_shade": shade,
            "shade_field": field,
            "shade_rows": self._grid[0],
            "shade_cols": self._grid[1],
            "sky": sky,
            "lit_at_start": lit,
            "lit_level": lit_level.astype(np.float32),
            "shadow_level": shadow_level.astype(np.float32),
            "shadow_ratio": ratio,
            "reference": self._reference,
        }


def cloud_shade(gain_median, gain_lit, gain_source, *, shadow_ratio):
    """Transmittance of the sun term under a cloud that covers every lit pixel, per frame.

    A lit pixel whose sky light is ``rho`` of its lit luminance reads ``rho + T (1 - rho)``
    of the lit gain under a cloud of transmittance ``T``; the median ratio of the lit
    pixels over the lit gain, with ``rho`` the pass's shadow-to-lit ratio, gives the median
    ``T``. Only in frames without an unclouded lit population (``gain_source`` 1), where it is
    the frame's shade field; where part of the lit pixels is unclouded the cloud's shade varies
    over the frame (:mod:`shadowcam.outdoor.shade_field`).

    Parameters
    ----------
    gain_median, gain_lit : (T,) ndarray
        The median ratio of every lit pixel (on the frame before registration) and the lit
        gain.
    gain_source : (T,) int ndarray
        :data:`GAIN_SOURCES` codes.
    shadow_ratio : float, keyword-only
        Median shadow-to-lit ratio of the pass (the lit pixels' sky share).

    Returns
    -------
    (T,) float64 ndarray
        In (0, 1]; 1 in the other frames.
    """
    median = np.asarray(gain_median, dtype=np.float64)
    lit = np.asarray(gain_lit, dtype=np.float64)
    source = np.asarray(gain_source)
    check_same_shape({"gain_median": median, "gain_lit": lit, "gain_source": source})
    covered = source == 1
    rho = float(np.clip(shadow_ratio, 0.0, 0.99))
    with np.errstate(divide="ignore", invalid="ignore"):
        shade = (median / lit - rho) / (1.0 - rho)
    return np.where(covered & np.isfinite(shade), np.clip(shade, 0.05, 1.0), 1.0)


def cloud_shades(gain_median, gain_lit, gain_source, shade_levels, *, shadow_ratio):
    """The cloud's shade of every frame: :func:`cloud_shade` and the field the tracker divides out.

    Parameters
    ----------
    gain_median, gain_lit : (T,) ndarray
    gain_source : (T,) int ndarray
        As :func:`cloud_shade`.
    shade_levels : (T, By, Bx) ndarray
        The blocks' lit levels (:func:`shadowcam.outdoor.shade_field.block_levels`).
    shadow_ratio : float, keyword-only

    Returns
    -------
    cloud_shade : (T,) float64 ndarray
    shade_field : (T, By, Bx) float32 ndarray
        Uniform (``cloud_shade``) in the frames whose lit gain comes from the sky gain (a cloud
        over every lit pixel, ``gain_source`` 1), else the blocks' transmittance
        (:func:`shadowcam.outdoor.shade_field.shade_field`).
    """
    shade = cloud_shade(gain_median, gain_lit, gain_source, shadow_ratio=shadow_ratio)
    covered = (np.asarray(gain_source) == 1)[:, None, None]
    field = np.where(covered, shade[:, None, None].astype(np.float32),
                     shade_field(shade_levels, gain_lit, shadow_ratio=shadow_ratio))
    return shade, field


def clouded_reference_gains(gain_lit, gain_sky, gain_source, *, settled=CLOUDED_REFERENCE):
    """The lit gains of the first frames when the reference's lit pixels were under a cloud.

    The lit gain is measured against the reference's lit pixels; under a cloud over all of them
    in the reference, the frames that follow read the clouded level as the lit one until the
    cloud has left, when the lit-to-sky gain ratio ``gain_lit / gain_sky`` jumps up. A cloud
    only removes sunlight, so the unclouded ratio of a frame is at least that of any frame
    measured under the cloud: the frames from the first on whose ratio lies below `settled`
    times the highest ratio of the frames from them on (the sunset lowers the sun's share, it
    does not raise it) took the cloud's level for the lit one. Their lit gain becomes the sky
    gain times that highest ratio, and their source ``1`` (a cloud over every lit pixel: its
    shade is :func:`cloud_shade`'s).

    Parameters
    ----------
    gain_lit, gain_sky : (T,) ndarray
    gain_source : (T,) int ndarray
        :data:`GAIN_SOURCES` codes.
    settled : float, optional
        Fraction of the later ratio below which a first frame's ratio counts as clouded.

    Returns
    -------
    gain_lit : (T,) float64 ndarray
    gain_source : (T,) int8 ndarray
    """
    lit = np.asarray(gain_lit, dtype=np.float64)
    sky = np.asarray(gain_sky, dtype=np.float64)
    source = np.asarray(gain_source, dtype=np.int8)
    check_same_shape({"gain_lit": lit, "gain_sky": sky, "gain_source": source})
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(sky > 0, lit / sky, np.nan)
    later = np.fmax.accumulate(ratio[::-1])[::-1]
    clouded = np.logical_and.accumulate(ratio < settled * later)  # a prefix from the first frame
    if not clouded.any():
        return lit, source
    lit, source = lit.copy(), source.copy()
    lit[clouded] = sky[clouded] * later[clouded]
    source[clouded] = 1
    return lit, source


def merge_parts(parts):
    """Merge the results of time parts of the first pass (exactly: concatenation and minimum).

    Parameters
    ----------
    parts : sequence of dict
        :meth:`SequenceNormaliser.partial` of consecutive parts covering frames
        ``0 .. T-1`` (any order; ``reference`` is needed in one of them). To
        hold one part at a time, feed :class:`PartMerger` instead.

    Returns
    -------
    dict
        As :func:`normalise_frames`.
    """
    merger = PartMerger()
    for part in sorted(parts, key=lambda part: part["first_frame"]):
        merger.add(part)
    return merger.result()


def normalise_frames(frames, **options):
    """Run :class:`SequenceNormaliser` over `frames`.

    Parameters
    ----------
    frames : iterable of (H, W, C) ndarray
        In time order (e.g. flattened :func:`shadowcam.io.frame_store.iter_frame_chunks`);
        frames after the first may be given as their ``(H, W)`` luminance.
    **options
        Keyword options of :class:`SequenceNormaliser`.

    Returns
    -------
    dict
        ``shift (T, 2)`` (row, col; pixels), ``gain_lit (T,)``, ``gain_sky (T,)``,
        ``kept_lit (T,)`` (pixels used for the lit gain), ``gain_source (T,)`` (int8, where
        the lit gain comes from: :data:`GAIN_SOURCES`), ``gain_median (T,)`` (median ratio of
        every lit pixel), ``cloud_shade (T,)`` (:func:`cloud_shade`), ``shade_levels`` and
        ``shade_field (T, By, Bx)`` with ``shade_rows (By,)``, ``shade_cols (Bx,)`` (block centres,
        frame pixels; :mod:`shadowcam.outdoor.shade_field`: ``cloud_shade`` where ``gain_source``
        is 1), ``sky``,
        ``lit_at_start (H, W)`` bool, ``lit_level``, ``shadow_level (H, W)``
        (luminance of the reference frame's scale: lit in the reference, and
        sky-lit, normalised by ``gain_sky``), ``shadow_ratio`` (median
        shadow / lit level) and ``reference (H, W, C)``.
    """
    normaliser = SequenceNormaliser(**options)
    for frame in frames:
        normaliser.update(frame)
    return normaliser.result()


def normalise_part(frames, *, start, stop, reference=None, overlap=2, **options):
    """First pass over one time part ``start .. stop - 1`` (a job of its own).

    Parameters
    ----------
    frames : iterable of (H, W, C) or (H, W) ndarray
        Frames ``max(0, start - overlap) .. stop - 1`` in time order, in colour
        or as luminance (frame 0 in colour)
        (:func:`part_frames` gives the range).
    start, stop : int
        Frames recorded by this part.
    reference : (H, W, C) ndarray, optional
        Frame 0 (needed when ``start - overlap > 0``).
    overlap : int, optional
        Warm-up frames before `start` (>= 2: the 3-frame windows of the running
        minimum, and the gain and shift searches start from the previous frame's).
    **options
        Other keyword options of :class:`SequenceNormaliser`.

    Returns
    -------
    dict
        :meth:`SequenceNormaliser.partial`, to merge with :func:`merge_parts`.
    """
    first, stop = part_frames(start, stop, overlap=overlap)
    normaliser = SequenceNormaliser(reference=reference if first > 0 else None, first_index=first,
                                    record_from=start, **options)
    fed = 0
    for frame in frames:
        normaliser.update(frame)
        fed += 1
    if fed != stop - first:
        raise ValueError(f"part {start}:{stop} with overlap {overlap} needs frames {first}..{stop - 1} "
                         f"({stop - first}); got {fed}")
    return normaliser.partial()


def part_frames(start, stop, *, overlap=2):
    """Return ``(first, stop)``: the frames a part ``start:stop`` reads (warm-up included)."""
    if not 0 <= start < stop:
        raise ValueError(f"part start {start} and stop {stop}: need 0 <= start < stop")
    if overlap < 2:
        raise ValueError(f"overlap must be >= 2 frames; got {overlap}")
    return max(0, start - overlap), stop


def aligned_luminance(frame, shift):
    """Registered luminance ``(H, W)`` float32 of `frame` ``(H, W, C)`` given its shift (row, col)."""
    return translate(luminance(frame), shift, method="cubic_Keys1981")
