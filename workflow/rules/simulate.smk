rule compile_kernels:
    input:
        KERNEL_CASES,
    output:
        touch(f"{R}/.kernels_compiled"),
    log:
        f"{R}/logs/compile_kernels.log",
    params:
        solver=SOLVER_HASH,  # the kernels are cached per solver hash: a new solver compiles anew
    shell:
        f"{PY} -m solver warm {{input}} 2> {{log}}"


rule case_file:
    output:
        f"{R}/cases/{{case}}/case.yaml",
    log:
        f"{R}/logs/case_file_{{case}}.log",
    params:
        text=case_yaml,  # a change of this case's settings rewrites it (and reruns the case)
        config=CONFIG_FILE,
    shell:
        f"{PY} -m study case-file {{params.config}} {{wildcards.case}} -o {{output}} 2> {{log}}"


# A run resumes from its checkpoint (outside output:, which Snakemake deletes before a rerun)
# and shows its progress to python -m study status.
rule run_case:
    input:
        case=f"{R}/cases/{{case}}/case.yaml",
        kernels=ancient(f"{R}/.kernels_compiled"),  # compiled first; a recompile reruns nothing
        warm=warm_input,
    output:
        f"{R}/cases/{{case}}/run.nc",
    log:
        f"{R}/logs/run_{{case}}.log",
    params:
        solver=SOLVER_HASH,
    priority: run_priority
    threads: RES["threads"]
    resources:
        runtime=RES["runtime_min"],
        mem_mb=RES["mem_mb"],
    shell:
        (f"NUMBA_NUM_THREADS={{threads}} {PY} -m solver {FLOW.solver} {{input.case}} -o {{output}} "
         f"--threads {{threads}} --quiet --allow-diverged --checkpoint {R}/checkpoints/{{wildcards.case}}.ckpt "
         f"--progress {R}/progress/{{wildcards.case}}.json 2> {{log}}")
