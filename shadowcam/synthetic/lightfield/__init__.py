"""Synthetic light-field captures with exact ground truth.

Modules
-------
source : a reflector source (ray family with caustic rings), ground-truth irradiance and far field.
capture : screens, camera, wire sweeps, HDR RAW brackets; DNG writer of a capture.
"""
