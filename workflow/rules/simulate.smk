rule compile_kernels:
    input:
        expand("results/cases/{case}/case.yaml", case=CASE_IDS),  # their settings are compiled too
    output:
        touch("results/.kernels_compiled"),
    log:
        "results/logs/compile_kernels.log",
    params:
        solver=SOLVER_HASH,  # the kernels are cached per solver hash: a new solver compiles anew
    shell:
        "python -m solver warm {input} 2> {log}"


rule case_file:
    output:
        "results/cases/{case}/case.yaml",
    log:
        "results/logs/case_file_{case}.log",
    params:
        text=case_yaml,  # a change of this case's settings rewrites it (and reruns the case)
        config=CONFIG_FILE,
    shell:
        "python -m study case-file {params.config} {wildcards.case} -o {output} 2> {log}"


rule run_case:
    input:
        case="results/cases/{case}/case.yaml",
        kernels=ancient("results/.kernels_compiled"),  # compiled first; a recompile reruns nothing
        warm=warm_input,
    output:
        "results/cases/{case}/run.nc",
    log:
        "results/logs/run_{case}.log",
    params:
        solver=SOLVER_HASH,
    priority: run_priority
    threads: RES["threads"]
    resources:
        runtime=RES["runtime_min"],
        mem_mb=RES["mem_mb"],
    shell:
        RUN_COMMAND
