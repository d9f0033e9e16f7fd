"""``shadowcam plan``: dual resolution of a planned capture and the mask speed for a wanted one.

Usage (all lengths in one unit, e.g. metres; speed per second; frame time in seconds)::

    shadowcam plan --pixel-width 5.9e-6 --mask-distance 0.3 --depth 2.0 \\
        --focal-length 0.035 --frame-time 0.04 --image-pixels 4000 \\
        [--mask-speed 0.002] [--wanted-dual-pixels 500]

Prints the paper's Eq. 3 (section II-B): r = W h (D - f) / (f D u t) dual pixels per
camera pixel, the dual pixels and frames per sweep, and the recommended mask speed.

Offers
------
add_parser : register the step and its options.
run : evaluate and print the plan.
"""


def add_parser(subparsers, name):
    """Register ``plan`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="resolution planning (paper Eq. 3)",
                                   description=__doc__.split("\n\n")[0].strip("`"))
    parser.add_argument("--pixel-width", type=float, required=True, help="W, sensor pixel width")
    parser.add_argument("--mask-distance", type=float, required=True,
                        help="h, light-to-mask distance")
    parser.add_argument("--depth", type=float, required=True, help="D, greatest scene depth")
    parser.add_argument("--focal-length", type=float, required=True, help="f, focal length")
    parser.add_argument("--frame-time", type=float, required=True,
                        help="t, seconds per frame (the mask moves u t per frame)")
    parser.add_argument("--image-pixels", type=int, required=True,
                        help="camera pixels across the swept direction")
    parser.add_argument("--mask-speed", type=float, default=None, help="u, planned mask speed")
    parser.add_argument("--wanted-dual-pixels", type=float, default=None,
                        help="wanted dual pixels across the sweep")
    return parser


def run(args):
    """Print the plan."""
    from shadowcam.lab.planning import plan_capture

    plan = plan_capture(pixel_width=args.pixel_width, mask_distance=args.mask_distance,
                        depth=args.depth, focal_length=args.focal_length,
                        frame_time=args.frame_time, image_pixels=args.image_pixels,
                        mask_speed=args.mask_speed, wanted_dual_pixels=args.wanted_dual_pixels)
    if "ratio" in plan:
        print(f"mask speed u = {plan['mask_speed']:.6g} per s")
        print(f"  r = {plan['ratio']:.4g} dual pixels per camera pixel (Eq. 3)")
        print(f"  dual resolution across the sweep = {plan['dual_pixels']:.1f} pixels "
              f"({plan['frames_per_sweep']:.1f} frames for the shadow to cross the image)")
        if plan["exceeds_camera"]:
            print("  warning: r > 1, the dual view asks for more pixels than the camera "
                  "resolves (holes); move the mask faster")
    if "recommended_mask_speed" in plan:
        print(f"for {plan['wanted_dual_pixels']:.0f} dual pixels across "
              f"{plan['image_pixels']} camera pixels (r = {plan['recommended_ratio']:.4g}):")
        print(f"  recommended mask speed u = {plan['recommended_mask_speed']:.6g} per s "
              f"({plan['mask_step_per_frame']:.6g} per frame)")
        if plan["recommended_exceeds_camera"]:
            print("  warning: more dual pixels than camera pixels (r > 1): the dual view "
                  "will have holes")
