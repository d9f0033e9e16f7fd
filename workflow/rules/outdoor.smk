# Stages of an outdoor time-lapse (manifest kind: outdoor): registration and
# photometric normalisation, shadow-edge tracking with keyframe interpolation,
# the per-pixel arrival-time map, the ridge pushbroom, accuracy (datasets with
# ground truth) and the report figures (paper Fig. 18). The frames come from
# the shared `decode` rule (results/{ds}/frames/<sweep>.zarr).


rule outdoor_normalise:
    input:
        capture=get_capture_input,
        frames=get_outdoor_frames,
    output:
        "results/{ds}/outdoor/photometry.nc",
    params:
        manifest=get_capture_manifest,
        options=as_json(config["outdoor"]["normalise"]),
    resources:
        mem_mb=get_stream_mem_mb,
        runtime=get_stream_runtime,
    log:
        "logs/{ds}/outdoor_normalise.log",
    benchmark:
        "benchmarks/{ds}/outdoor_normalise.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam outdoor-normalise --manifest {params.manifest} --frames {input.frames}"
        " --params {params.options:q} --out {output} > {log} 2>&1"


rule track_edges:
    input:
        frames=get_outdoor_frames,
        photometry="results/{ds}/outdoor/photometry.nc",
    output:
        "results/{ds}/outdoor/edges.nc",
    params:
        options=as_json(config["outdoor"]["track_edges"]),
    resources:
        mem_mb=get_stream_mem_mb,
        runtime=get_stream_runtime,
    log:
        "logs/{ds}/track_edges.log",
    benchmark:
        "benchmarks/{ds}/track_edges.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam track-edges --frames {input.frames} --photometry {input.photometry}"
        " --params {params.options:q} --out {output} > {log} 2>&1"


rule arrival:
    input:
        photometry="results/{ds}/outdoor/photometry.nc",
        edges="results/{ds}/outdoor/edges.nc",
    output:
        "results/{ds}/outdoor/arrival.nc",
    params:
        options=as_json(config["outdoor"]["arrival"]),
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    log:
        "logs/{ds}/arrival.log",
    benchmark:
        "benchmarks/{ds}/arrival.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam arrival --photometry {input.photometry} --edges {input.edges}"
        " --params {params.options:q} --out {output} > {log} 2>&1"


rule pushbroom:
    input:
        photometry="results/{ds}/outdoor/photometry.nc",
        edges="results/{ds}/outdoor/edges.nc",
    output:
        nc="results/{ds}/outdoor/pushbroom.nc",
        png="results/{ds}/outdoor/pushbroom.png",
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    log:
        "logs/{ds}/pushbroom.log",
    benchmark:
        "benchmarks/{ds}/pushbroom.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam pushbroom --photometry {input.photometry} --edges {input.edges}"
        " --out {output.nc} --png {output.png} > {log} 2>&1"


rule outdoor_accuracy:
    input:
        capture=get_capture_input,
        frames=get_outdoor_frames,
        photometry="results/{ds}/outdoor/photometry.nc",
        edges="results/{ds}/outdoor/edges.nc",
        arrival="results/{ds}/outdoor/arrival.nc",
        pushbroom="results/{ds}/outdoor/pushbroom.nc",
    output:
        json="results/{ds}/outdoor/accuracy.json",
        csv=report(
            "results/{ds}/outdoor/accuracy.csv",
            caption="../report/outdoor_accuracy.rst",
            category="{ds}",
            subcategory="accuracy",
            labels={"dataset": "{ds}", "table": "outdoor accuracy (CSV)"},
        ),
    params:
        manifest=get_capture_manifest,
        options=as_json(config["outdoor"]["accuracy"]),
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    log:
        "logs/{ds}/outdoor_accuracy.log",
    benchmark:
        "benchmarks/{ds}/outdoor_accuracy.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam outdoor-accuracy --manifest {params.manifest} --frames {input.frames}"
        " --photometry {input.photometry} --edges {input.edges} --arrival {input.arrival}"
        " --pushbroom {input.pushbroom} --params {params.options:q}"
        " --out-json {output.json} --out-csv {output.csv} > {log} 2>&1"


rule outdoor_figures:
    input:
        frames=get_outdoor_frames,
        photometry="results/{ds}/outdoor/photometry.nc",
        edges="results/{ds}/outdoor/edges.nc",
        arrival="results/{ds}/outdoor/arrival.nc",
        pushbroom="results/{ds}/outdoor/pushbroom.nc",
        accuracy=get_outdoor_accuracy,
    output:
        report(
            directory("results/{ds}/outdoor/figures"),
            patterns=["{figure}.png", "{figure}.html"],
            caption="../report/outdoor_figures.rst",
            category="{ds}",
            subcategory="figures",
            labels={"dataset": "{ds}", "figure": "{figure}"},
        ),
    params:
        accuracy=get_outdoor_accuracy_option,
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    log:
        "logs/{ds}/outdoor_figures.log",
    benchmark:
        "benchmarks/{ds}/outdoor_figures.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam outdoor-figures --frames {input.frames} --photometry {input.photometry}"
        " --edges {input.edges} --arrival {input.arrival} --pushbroom {input.pushbroom}"
        " {params.accuracy} --outdir {output} > {log} 2>&1"
