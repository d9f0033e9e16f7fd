# Stage: decode each sweep once into a time-chunked zarr frame store, and the
# unshadowed reference frame (when the capture has one) into its own store.
# A sweep is decoded in time parts, one job each (decode_part: frames START:STOP into
# a part store); `decode` joins the parts by hard-linking their chunk files, so the
# sweep store equals a single-job decode bit for bit. A sweep of more than
# PARTS_PER_GROUP parts is joined in two levels (decode_group, then decode), with the
# same result. Part sizes and groups: parts.smk, which
# also says why a user capture's frames are a param of `decode`, not inputs.

# reference.zarr is a single image, not a sweep (wildcard `sweep` never matches it):
# decode_reference makes it.


rule decode_part:
    input:
        get_part_files,
    output:
        temp(directory("results/{ds}/frames/{sweep}.parts/{part}.zarr")),
    log:
        "logs/{ds}/decode_{sweep}_part{part}.log",
    benchmark:
        "benchmarks/{ds}/decode_{sweep}_part{part}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_decode_mem_mb,
        runtime=get_decode_runtime,
    params:
        manifest=get_capture_manifest,
        chunk_frames=get_chunk_frames,
        frames=get_part_range,
    shell:
        "shadowcam decode --manifest {params.manifest} --sweep {wildcards.sweep}"
        " --chunk-frames {params.chunk_frames} --frames {params.frames} --out {output} > {log} 2>&1"


rule decode_group:
    input:
        get_group_parts,
    output:
        temp(directory("results/{ds}/frames/{sweep}.groups/{group}.zarr")),
    log:
        "logs/{ds}/decode_{sweep}_group{group}.log",
    benchmark:
        "benchmarks/{ds}/decode_{sweep}_group{group}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=1024,
        runtime=10,
    shell:
        "shadowcam merge-frames --parts {input} --out {output} > {log} 2>&1"


rule decode:
    input:
        get_decode_parts,
    output:
        directory("results/{ds}/frames/{sweep}.zarr"),
    log:
        "logs/{ds}/decode_{sweep}.log",
    benchmark:
        "benchmarks/{ds}/decode_{sweep}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=1024,
        runtime=10,
    params:
        frames_stamp=get_sweep_stamp,
    shell:
        "shadowcam merge-frames --parts {input} --out {output} > {log} 2>&1"


rule decode_reference:
    input:
        get_reference_files,
    output:
        directory("results/{ds}/frames/reference.zarr"),
    log:
        "logs/{ds}/decode_reference.log",
    benchmark:
        "benchmarks/{ds}/decode_reference.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_image_mem_mb,
        runtime=10,
    params:
        manifest=get_capture_manifest,
    shell:
        "shadowcam decode --manifest {params.manifest} --sweep reference --out {output} > {log} 2>&1"
