"""The outdoor renderer: terrain, sun, sunset frames with nuisances, exact ground truth.

Modules
-------
capture : A whole synthetic outdoor time-lapse: noise-free frames with nuisances, and its ground truth.
nuisance : nuisances of real time-lapse captures, each switchable and recorded per frame.
render : synthetic outdoor sunset time-lapse: scene, static geometry, sun visibility, frame radiance.
sample : real-size outdoor time-lapse samples for throughput and memory benchmarks.
sun : the sun: ephemeris (direction toward the sun at any time) and its sunset colour.
terrain : terrain heightfields for synthetic outdoor captures: procedural ridge/cliff, rays, horizons.
truth : exact ground truth of a synthetic outdoor time-lapse (definitions of dev_ridge's gt.npz).
"""
