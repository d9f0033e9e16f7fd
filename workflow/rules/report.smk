# Stage: report figures (primal image, shadow-time maps, dual view vs reciprocal,
# error histogram, accuracy table) shown by `snakemake --report results/report.html`.


rule report_figures:
    input:
        capture=get_capture_input,
        shadow_time="results/{ds}/shadow_time.nc",
        dual_view="results/{ds}/dual_view.nc",
        dual_coords="results/{ds}/dual_coords.nc",
        reference=get_reference,
        accuracy=get_accuracy,
        viewpoints=get_viewpoint_products,
    output:
        report(
            directory("results/{ds}/figures"),
            patterns=["{figure}.png", "{figure}.html"],
            caption="../report/figures.rst",
            category="{ds}",
            subcategory="figures",
            labels=get_figure_labels,
        ),
    log:
        "logs/{ds}/report_figures.log",
    benchmark:
        "benchmarks/{ds}/report_figures.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    params:
        manifest=get_capture_manifest,
        reference=get_flag("--reference", "reference"),
        accuracy=get_flag("--accuracy", "accuracy"),
        viewpoints=get_viewpoint_flags,
    shell:
        "shadowcam report-figures --manifest {params.manifest} --shadow-time {input.shadow_time}"
        " --dual-view {input.dual_view} --dual-coords {input.dual_coords} {params.reference} {params.accuracy}"
        " {params.viewpoints} --outdir {output} > {log} 2>&1"
