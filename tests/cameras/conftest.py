"""Fixtures of the camera tests: rendered sweeps and their measured shadow times.

Offers
------
timed_capture(description, noise_std=0, supersample=2) : render the capture a description
    asks for (``synthetic.lab.scene.scene_from_description``, no calibration sweeps), time
    every sweep with ``lab.shadow_time`` and return ``(scene, ground_truth, shadow_time,
    reference)``; frames get seeded Gaussian noise of `noise_std` (linear units of the
    brightest reference pixel). Cached per arguments (the machine is shared).
"""

import json

import numpy as np
import pytest

from shadowcam.lab.shadow_time import shadow_time_dataset, sweep_shadow_times
from shadowcam.synthetic.lab.render import prepare_capture
from shadowcam.synthetic.lab.scenes import scene_from_description


@pytest.fixture(scope="session")
def timed_capture():
    cache = {}

    def make(description, *, noise_std=0.0, supersample=2):
        key = (json.dumps(description, sort_keys=True), float(noise_std), int(supersample))
        if key not in cache:
            scene = scene_from_description(description)
            capture = prepare_capture(scene, supersample=supersample, calibration=False)
            rng = np.random.default_rng(7)
            scale = float(capture.reference.max())
            per_sweep = {}
            for name in capture.sweep_names:
                frames = capture.frames(name)
                if noise_std:
                    frames = frames + rng.normal(0.0, noise_std * scale, frames.shape).astype(np.float32)
                per_sweep[name] = sweep_shadow_times([frames], frames.shape[1:3])
            cache[key] = (scene, capture.ground_truth, shadow_time_dataset(per_sweep), capture.reference)
        return cache[key]

    return make
