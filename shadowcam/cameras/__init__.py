"""Shadow cameras: the mappings from per-pixel shadow events to virtual-image coordinates,
and the images assembled on those coordinates (dual views, pushbrooms).

Modules
-------
models : the shadow-camera models (perspective, orthographic, linear, cross-slit, pushbroom) and
    the choice of one from a capture description.
dual_coords : shadow times -> dual (shadow-camera) coordinates ``u, v``.
intrinsics : virtual intrinsics (skew, aspect, size) of the output; skew and stretch measured.
accuracy : camera-specific checks (straightness primal vs dual, parallelism, redundancy gain).
dual_view : dual view: resample camera colours onto the ``(v, u)`` dual grid.
pushbroom : the image along the moving shadow edge: outdoor ridge (Fig. 18) and lab single sweep (Fig. 10).
straightness : straightness of straight scene edges in an image: do straight lines stay straight?
"""
