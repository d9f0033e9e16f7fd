# Stage: decode each sweep once into a time-chunked zarr frame store, and the
# unshadowed reference frame (when the capture has one) into its own store.

# reference.zarr is a single image, not a sweep: decode_reference makes it.
ruleorder: decode_reference > decode


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


rule decode_reference:
    input:
        get_reference_files,
    output:
        directory("results/{ds}/frames/reference.zarr"),
    params:
        manifest=get_capture_manifest,
    log:
        "logs/{ds}/decode_reference.log",
    benchmark:
        "benchmarks/{ds}/decode_reference.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam decode --manifest {params.manifest} --sweep reference --out {output} > {log} 2>&1"
