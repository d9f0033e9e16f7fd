# Stage (on request): speed against error of every shadow-time and dual-view resampling
# method on one dataset with ground truth; the chart's Pareto front justifies the defaults.
# Target: results/<ds>/methods/speed_vs_error.png (not part of `all`: it reruns every method).


rule methods_comparison:
    input:
        capture=get_capture_input,
        frames=get_scene_frames,
        shadow_time="results/{ds}/shadow_time.nc",
        dual_coords="results/{ds}/dual_coords.nc",
        reference=get_reference,
    output:
        dataset="results/{ds}/methods/methods.nc",
        csv=report(
            "results/{ds}/methods/methods.csv",
            caption="../report/methods.rst",
            category="{ds}",
            subcategory="methods",
            labels={"dataset": "{ds}", "table": "methods (CSV)"},
        ),
        figure=report(
            "results/{ds}/methods/speed_vs_error.png",
            caption="../report/methods.rst",
            category="{ds}",
            subcategory="methods",
            labels={"dataset": "{ds}", "figure": "speed against error"},
        ),
    log:
        "logs/{ds}/methods_comparison.log",
    benchmark:
        "benchmarks/{ds}/methods_comparison.tsv"
    conda:
        "../envs/shadowcam.yaml"
    params:
        manifest=get_capture_manifest,
        sweeps=get_scene_sweeps,
        reference=get_flag("--reference", "reference"),
        options=get_methods_params,
    shell:
        "shadowcam methods-comparison --manifest {params.manifest} --frames {input.frames}"
        " --sweeps {params.sweeps} --shadow-time {input.shadow_time} --dual-coords {input.dual_coords}"
        " {params.reference} --params {params.options:q} --out {output.dataset} --csv {output.csv}"
        " --figure {output.figure} > {log} 2>&1"
