"""Shadow cameras: the mappings from per-pixel shadow events to virtual-image coordinates,
and the images assembled on those coordinates (dual views, pushbrooms).

Modules
-------
dual_coords : shadow times -> dual (shadow-camera) coordinates ``u, v``.
dual_view : dual view: resample camera colours onto the ``(v, u)`` dual grid.
pushbroom : ridge pushbroom (paper section VII, Fig. 18): the image along the moving shadow edge.
straightness : straightness of straight scene edges in an image: do straight lines stay straight?
"""
