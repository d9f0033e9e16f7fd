# Stages of an outdoor time-lapse (manifest kind: outdoor): registration and
# photometric normalisation (the sky mask once per sweep, then one job per time span of config outdoor.part_frames
# frames, then an exact merge), shadow-edge tracking with keyframe interpolation
# (one job per column strip of config outdoor.edge_strips, merged exactly),
# the per-pixel arrival-time map, the ridge pushbroom, accuracy (datasets with
# ground truth) and the report figures (paper Fig. 18). The frames come from
# the shared `decode` rule (results/{ds}/frames/<sweep>.zarr).


rule outdoor_sky_mask:
    input:
        capture=get_capture_input,
        frames=get_outdoor_frames,
    output:
        "results/{ds}/outdoor/sky_mask.nc",
    log:
        "logs/{ds}/outdoor_sky_mask.log",
    benchmark:
        "benchmarks/{ds}/outdoor_sky_mask.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_normalise_mem_mb,
        runtime=10,
    params:
        manifest=get_capture_manifest,
        options=as_json(config["outdoor"]["normalise"]),
    shell:
        "shadowcam outdoor-sky-mask --manifest {params.manifest} --frames {input.frames}"
        " --params {params.options:q} --out {output} > {log} 2>&1"


rule outdoor_normalise_part:
    input:
        capture=get_capture_input,
        frames=get_outdoor_frames,
        sky="results/{ds}/outdoor/sky_mask.nc",
    output:
        temp("results/{ds}/outdoor/photometry.parts/{span}.nc"),
    log:
        "logs/{ds}/outdoor_normalise_part{span}.log",
    benchmark:
        "benchmarks/{ds}/outdoor_normalise_part{span}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_normalise_mem_mb,
        runtime=get_normalise_runtime,
    params:
        manifest=get_capture_manifest,
        span=get_outdoor_span_range,
        options=as_json(config["outdoor"]["normalise"]),
    shell:
        "shadowcam outdoor-normalise --manifest {params.manifest} --frames {input.frames}"
        " --sky {input.sky} --part {params.span} --params {params.options:q} --out {output} > {log} 2>&1"


rule outdoor_normalise:
    input:
        get_outdoor_photometry_parts,
    output:
        "results/{ds}/outdoor/photometry.nc",
    log:
        "logs/{ds}/outdoor_normalise.log",
    benchmark:
        "benchmarks/{ds}/outdoor_normalise.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_per_pixel_mem_mb,
        runtime=10,
    shell:
        "shadowcam outdoor-merge-photometry --parts {input} --out {output} > {log} 2>&1"


rule track_edges_strip:
    input:
        frames=get_outdoor_frames,
        photometry="results/{ds}/outdoor/photometry.nc",
    output:
        temp("results/{ds}/outdoor/edges.strips/{strip}.npz"),
    log:
        "logs/{ds}/track_edges_strip{strip}.log",
    benchmark:
        "benchmarks/{ds}/track_edges_strip{strip}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_track_strip_mem_mb,
        runtime=get_track_strip_runtime,
    params:
        strip=get_edge_strip_arg,
        options=as_json(config["outdoor"]["track_edges"]),
    shell:
        "shadowcam track-edges-strip --frames {input.frames} --photometry {input.photometry}"
        " --strip {params.strip} --params {params.options:q} --out {output} > {log} 2>&1"


rule track_edges:
    input:
        frames=get_outdoor_frames,
        photometry="results/{ds}/outdoor/photometry.nc",
        strips=get_edge_strips,
    output:
        "results/{ds}/outdoor/edges.nc",
    log:
        "logs/{ds}/track_edges.log",
    benchmark:
        "benchmarks/{ds}/track_edges.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_track_edges_mem_mb,
        runtime=get_track_edges_runtime,
    params:
        options=as_json(config["outdoor"]["track_edges"]),
        strips=get_flag("--strips", "strips"),
    shell:
        "shadowcam track-edges --frames {input.frames} --photometry {input.photometry}"
        " {params.strips} --params {params.options:q} --out {output} > {log} 2>&1"


rule arrival:
    input:
        photometry="results/{ds}/outdoor/photometry.nc",
        edges="results/{ds}/outdoor/edges.nc",
    output:
        "results/{ds}/outdoor/arrival.nc",
    log:
        "logs/{ds}/arrival.log",
    benchmark:
        "benchmarks/{ds}/arrival.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_per_pixel_mem_mb,
        runtime=get_per_pixel_runtime,
    params:
        options=as_json(config["outdoor"]["arrival"]),
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
    log:
        "logs/{ds}/pushbroom.log",
    benchmark:
        "benchmarks/{ds}/pushbroom.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_per_pixel_mem_mb,
        runtime=get_per_pixel_runtime,
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
        # shown in the report as the figure "accuracy" (HTML); a CSV there only downloads
        csv="results/{ds}/outdoor/accuracy.csv",
    log:
        "logs/{ds}/outdoor_accuracy.log",
    benchmark:
        "benchmarks/{ds}/outdoor_accuracy.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_per_pixel_mem_mb,
        runtime=get_per_pixel_runtime,
    params:
        manifest=get_capture_manifest,
        options=as_json(config["outdoor"]["accuracy"]),
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
        capture=get_capture_input,
    output:
        report(
            directory("results/{ds}/outdoor/figures"),
            patterns=["{figure}.png", "{figure}.html"],
            caption="../report/outdoor_figures.rst",
            category="{ds}",
            subcategory="figures",
            labels=get_figure_labels,
        ),
    log:
        "logs/{ds}/outdoor_figures.log",
    benchmark:
        "benchmarks/{ds}/outdoor_figures.tsv"
    conda:
        "../envs/shadowcam.yaml"
    threads: 1
    resources:
        mem_mb=get_per_pixel_mem_mb,
        runtime=get_per_pixel_runtime,
    params:
        accuracy=get_flag("--accuracy", "accuracy"),
        manifest=get_capture_manifest,
    shell:
        "shadowcam outdoor-figures --frames {input.frames} --photometry {input.photometry}"
        " --edges {input.edges} --arrival {input.arrival} --pushbroom {input.pushbroom}"
        " {params.accuracy} --manifest {params.manifest} --outdir {output} > {log} 2>&1"
