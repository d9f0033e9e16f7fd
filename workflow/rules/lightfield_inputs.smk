# Input functions and final targets of the light-field stage (workflow/rules/lightfield.smk),
# from the capture plan of a kind: lightfield manifest.


def _lightfield_plan(ds):
    plan = capture(ds)
    if not plan.is_lightfield:
        raise ValueError(f"dataset {ds!r} is not a light-field capture (manifest kind)")
    return plan


def get_lightfield_sources(wildcards):
    """What the capture folder is made from: the manifest, and a captured light field's files."""
    plan = _lightfield_plan(wildcards.ds)
    files = [f for sweep in plan.sweeps.values() for f in sweep.files]
    return [manifest_path(wildcards.ds)] + relative(files)


def get_lightfield_capture(wildcards):
    """The light-field capture folder (with capture.json) of dataset `ds`."""
    _lightfield_plan(wildcards.ds)
    return f"results/{wildcards.ds}/lightfield/capture"


def lightfield_files(ds, folder, suffix):
    """One file per sweep of light-field dataset `ds`: results/{ds}/lightfield/{folder}/{sweep}{suffix}."""
    sweeps = _lightfield_plan(ds).sweeps
    return [f"results/{ds}/lightfield/{folder}/{s}{suffix}" for s in sweeps]


def get_lightfield_sweeps(wildcards):
    """Shadow-time datasets of every screen and sweep."""
    return lightfield_files(wildcards.ds, "shadow_times", ".nc")


def get_lightfield_hdr(wildcards):
    """HDR stacks of every screen and sweep."""
    return lightfield_files(wildcards.ds, "hdr", ".npy")


def get_lightfield_truth(wildcards):
    """The ground truth of a rendered light field (for its report figures); none for a captured one."""
    if not _lightfield_plan(wildcards.ds).has_ground_truth:
        return []
    return f"results/{wildcards.ds}/lightfield/truth.nc"


def lightfield_targets(ds):
    """Final outputs of light-field dataset `ds` (list of str)."""
    out = f"results/{ds}/lightfield"
    targets = [f"{out}/rays.nc", f"{out}/renders.nc", f"{out}/source.ies"]
    targets += [f"{out}/source.ldt", f"{out}/figures"]
    if capture(ds).has_ground_truth:
        targets += [f"{out}/accuracy.json", f"{out}/accuracy.csv"]
    return targets
