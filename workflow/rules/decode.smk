# Stage: decode one sweep (or the reference frame) into a time-chunked zarr frame store.


rule decode:
    input:
        get_raw_files,
    output:
        directory("results/{ds}/frames/{sweep}.zarr"),
    params:
        manifest=get_capture_manifest,
        chunk_frames=config["decode"]["chunk_frames"],
    log:
        "logs/{ds}/decode_{sweep}.log",
    benchmark:
        "benchmarks/{ds}/decode_{sweep}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam decode --manifest {params.manifest} --sweep {wildcards.sweep}"
        " --chunk-frames {params.chunk_frames} --out {output} > {log} 2>&1"
