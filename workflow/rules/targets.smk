# Final outputs of each configured dataset (inputs of `all`); a lab capture ends in shadow
# times, dual coordinates, the dual view and figures (a single-sweep one in shadow times and
# the shadow pushbroom); a light field in its rays, renders, IES/LDT files and figures
# (lightfield.smk); an outdoor time-lapse in the
# arrival-time map, the ridge pushbroom and figures; both add accuracy when the dataset
# has ground truth. Stages a dataset does not need are not asked for.


def dataset_targets(ds):
    """Return the final output files of dataset `ds` (list of str)."""
    plan = capture(ds)
    if plan.is_lightfield:
        return lightfield_targets(ds)  # workflow/rules/lightfield.smk
    if plan.camera_array is not None:  # workflow/rules/array.smk
        names = ("camera_array.nc",)
        if plan.has_ground_truth:
            names += ("accuracy.json", "views.png")
        return [f"results/{ds}/array/{name}" for name in names]
    if plan.light_set is not None:  # workflow/rules/lights.smk
        names = ("light_views.nc",)
        if plan.has_ground_truth:
            names += ("accuracy.json", "lights.png")
        return [f"results/{ds}/lights/{name}" for name in names]
    if plan.is_outdoor:
        targets = [
            f"results/{ds}/outdoor/arrival.nc",
            f"results/{ds}/outdoor/pushbroom.nc",
            f"results/{ds}/outdoor/figures",
        ]
        accuracy = [
            f"results/{ds}/outdoor/accuracy.json",
            f"results/{ds}/outdoor/accuracy.csv",
        ]
    else:
        targets = [f"results/{ds}/shadow_time.nc"] + [
            f"results/{ds}/{stage}.nc" for stage in plan.stages
        ]
        targets += [] if plan.single_sweep else [f"results/{ds}/figures"]
        if "dual_view" in plan.stages:
            targets += [
                f"results/{ds}/viewpoints/{vp}/dual_view.nc"
                for vp in dataset_viewpoints(plan)
            ]
        accuracy = [f"results/{ds}/accuracy.json", f"results/{ds}/accuracy.csv"]
    return targets + (accuracy if plan.has_ground_truth else [])


def get_final_targets(wildcards):
    """Input function of `all`: the outputs of every configured dataset."""
    return [t for ds in config["datasets"] for t in dataset_targets(ds)]


#: stage outputs the lab accuracy step scores, and the option that passes each
ACCURACY_STAGE_FLAGS = {
    "dual_coords": "--dual-coords",
    "dual_view": "--dual-view",
    "pushbroom": "--pushbroom",
}


def get_accuracy_stages(wildcards):
    """Stage outputs the lab accuracy step scores: those the capture plan asks for."""
    plan = capture(wildcards.ds)
    return [f"results/{wildcards.ds}/{stage}.nc" for stage in plan.stages]


def get_accuracy_reference(wildcards):
    """Reference store the pushbroom was coloured with (single-sweep captures), else nothing."""
    return get_reference(wildcards) if capture(wildcards.ds).single_sweep else []


def _as_list(paths):
    return [paths] if isinstance(paths, str) else list(paths)


def get_accuracy_flags(wildcards, input):
    """``--dual-coords F --dual-view F`` or ``--pushbroom F [--reference R]`` of the accuracy step."""
    stages = capture(wildcards.ds).stages
    flags = [
        f"{ACCURACY_STAGE_FLAGS[stage]} {path}"
        for stage, path in zip(stages, _as_list(input.stages))
    ]
    flags += [f"--reference {path}" for path in _as_list(input.reference)]
    return " ".join(flags)


VIEWPOINT_PRODUCTS = ("shadow_time", "dual_coords", "dual_view")
OUTER_VIEWPOINTS = ("penumbra_first", "penumbra_last")


def dataset_viewpoints(plan):
    """The configured viewpoints a capture has: the source's extreme points
    (penumbra_first, penumbra_last) only under an extended light (``light: area``)."""
    extended = plan.camera.get("light") == "area"
    return [
        vp
        for vp in config["dual_view"]["viewpoints"]
        if extended or vp not in OUTER_VIEWPOINTS
    ]


def get_viewpoint_products(wildcards):
    """Shadow time, dual coordinates and dual view of each configured viewpoint."""
    plan = capture(wildcards.ds)
    if "dual_view" not in plan.stages:
        return []
    return [
        f"results/{wildcards.ds}/viewpoints/{vp}/{stem}.nc"
        for vp in dataset_viewpoints(plan)
        for stem in VIEWPOINT_PRODUCTS
    ]


def get_viewpoint_flags(wildcards, input):
    """``--viewpoint NAME SHADOW_TIME DUAL_COORDS DUAL_VIEW`` per viewpoint of the accuracy step."""
    paths = _as_list(input.viewpoints)
    n = len(VIEWPOINT_PRODUCTS)
    return " ".join(
        f"--viewpoint {path.split('/')[-2]} " + " ".join(paths[i : i + n])
        for i, path in zip(range(0, len(paths), n), paths[::n])
    )
