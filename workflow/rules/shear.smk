# Fig. 10 (Appendix B): 2-D shear flow, one job per case, then the figure.

SHEAR_PARAMS = [s.name for s in SHEAR if s.name not in ("cases", "seed")]  # settings.SHEAR: ShearConfig's fields


if "shear" in config:  # Fig. 10 exists only with a shear section

    rule simulate_shear:
        output:
            steps="results/shear/{case}/seed~{seed}/steps.parquet",
            state="results/shear/{case}/seed~{seed}/state.parquet",
        log:
            "logs/simulate_shear/{case}/seed~{seed}.log",
        benchmark:
            "results/benchmarks/simulate_shear/{case}/seed~{seed}.tsv"
        wildcard_constraints:
            case="|".join(SHEAR_CASES),
        priority: lambda w: shear_seconds(w.case, CONFIG.shear)  # the longest first
        conda:
            "../../envs/particle-entropy.yaml"
        resources:
            mem_mb=max(2000, shear_memory_mb(CONFIG.shear)),
            runtime=10,
        params:
            **{k: config["shear"][k] for k in SHEAR_PARAMS if k in config.get("shear", {})},
            code=script_code(SCRIPTS / "shear2d.py"),
        script:
            "../scripts/shear2d.py"

    rule plot_fig10:
        input:
            [f"results/shear/{case}/seed~{config['shear']['seed']}/state.parquet" for case in config["shear"]["cases"]],
        output:
            png=report(
                "figures/fig10.png",
                caption="../report/fig10.rst",
                category=FIGURE["fig10"].category,
                labels=figure_labels("fig10", "plot_fig10", FIGURE_DATA_PATTERN.format(fig="fig10")),
            ),
            pdf="figures/fig10.pdf",
            data=FIGURE_DATA_PATTERN.format(fig="fig10"),
        log:
            "logs/plot/fig10.log",
        benchmark:
            "results/benchmarks/plot/fig10.tsv"
        localrule: True
        conda:
            "../../envs/particle-entropy.yaml"
        resources:
            mem_mb=2000,
        params:
            code=script_code(SCRIPTS / "plot_fig10.py"),
        script:
            "../scripts/plot_fig10.py"
