# Final outputs of each configured dataset (inputs of `all`); a lab capture ends in shadow
# times, dual coordinates, the dual view and figures; an outdoor time-lapse in the
# arrival-time map, the ridge pushbroom and figures; both add accuracy when the dataset
# has ground truth. Stages a dataset does not need are not asked for.


def dataset_targets(ds):
    """Return the final output files of dataset `ds` (list of str)."""
    plan = capture(ds)
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
        targets = [
            f"results/{ds}/shadow_time.nc",
            f"results/{ds}/dual_coords.nc",
            f"results/{ds}/dual_view.nc",
            f"results/{ds}/figures",
        ]
        accuracy = [f"results/{ds}/accuracy.json", f"results/{ds}/accuracy.csv"]
    return targets + (accuracy if plan.has_ground_truth else [])


def get_final_targets(wildcards):
    """Input function of `all`: the outputs of every configured dataset."""
    return [t for ds in config["datasets"] for t in dataset_targets(ds)]
