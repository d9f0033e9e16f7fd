"""Synthetic light-field captures with exact ground truth.

Modules
-------
source : a reflector source (ray family with caustic rings), ground-truth irradiance and far field.
capture : screens, camera, wire sweeps, HDR RAW brackets; DNG writer of a capture.
truth : the ground truth on the grids a capture's renders and far field are scored on.
"""
