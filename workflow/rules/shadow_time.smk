# Stage: per-pixel shadow time of every sweep the dataset needs, in one dataset.
# The dips are tracked per time chunk (shadow_time_chunk, one job per sweep and decode
# part; DipTracker owning frames START:STOP, fed half a window more on each side), and
# shadow_time merges the partials (bit for bit the single-pass result), then classifies
# and times every pixel (edge_fit takes the capture description's pixel footprint, if it
# declares one, to time each pixel at its centre).


rule shadow_time_chunk:
    input:
        frames="results/{ds}/frames/{sweep}.zarr",
    output:
        temp("results/{ds}/shadow_time/{sweep}.parts/{part}.npz"),
    log:
        "logs/{ds}/shadow_time_{sweep}_part{part}.log",
    benchmark:
        "benchmarks/{ds}/shadow_time_{sweep}_part{part}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_shadow_time_chunk_mem_mb,
        runtime=get_shadow_time_chunk_runtime,
    params:
        owned=get_part_range,
        options=as_json(config["shadow_time"]["params"]),
    shell:
        "shadowcam shadow-time-chunk --frames {input.frames} --owned {params.owned}"
        " --params {params.options:q} --out {output} > {log} 2>&1"


rule shadow_time:
    input:
        frames=get_frames,
        partials=get_partials,
        capture=get_capture_input,
    output:
        "results/{ds}/shadow_time.nc",
    log:
        "logs/{ds}/shadow_time.log",
    benchmark:
        "benchmarks/{ds}/shadow_time.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_shadow_time_mem_mb,
        runtime=15,
    params:
        sweeps=get_sweeps,
        partials=get_partials_option,
        manifest=get_capture_manifest,
        method=config["shadow_time"]["method"],
        options=as_json(
            {**config["shadow_time"]["params"], "min_coverage": config["min_coverage"]}
        ),
    shell:
        "shadowcam shadow-time --frames {input.frames} --sweeps {params.sweeps} {params.partials}"
        " --method {params.method} --params {params.options:q} --manifest {params.manifest}"
        " --out {output} > {log} 2>&1"
