# figures/fig9_mechanism.png: the controlled experiments behind Fig. 9's minima and Fig. 8's late
# error (config `mechanism`; its COMIC tables come from rule comic_tables_section). Its own
# target: `snakemake -j2 figures/fig9_mechanism.png`.

if "mechanism" in config:

    rule fd_domain:
        """Fig. 8's FD grids on the paper's domain and on longer ones, at the same dx."""
        output:
            "results/tables/mechanism/fd_domain.parquet",
        log:
            "logs/fd_domain.log",
        benchmark:
            "results/benchmarks/fd_domain/all.tsv"
        conda:
            "../../envs/particle-entropy.yaml"
        params:
            n=config["mechanism"].get("fd_domain", {}).get("n", []),
            lengths=config["mechanism"].get("fd_domain", {}).get("lengths", []),
            fd_dt=config["time"]["fd_dt"],
            times=INPUTS.fd_report_times(),
            D=config["physics"]["D"],
            ref_length=config["physics"]["fd_length"],
            code=script_code(SCRIPTS / "fd_domain.py"),
        script:
            "../scripts/fd_domain.py"

    rule plot_fig9_mechanism:
        input:
            comic="results/tables/mechanism/comic.parquet",
            realisations="results/tables/mechanism/comic_realisations.parquet",
            fd="results/tables/mechanism/fd_domain.parquet" if "fd_domain" in config["mechanism"] else [],
            floors="results/tables/mechanism/floors.parquet" if "lattice" in config["mechanism"] else [],
        output:
            png=report(
                "figures/fig9_mechanism.png",
                caption="../report/fig9_mechanism.rst",
                category=FIGURE["fig9_mechanism"].category,
                labels=figure_labels(
                    "fig9_mechanism", "plot_fig9_mechanism", FIGURE_DATA_PATTERN.format(fig="fig9_mechanism")
                ),
            ),
            pdf="figures/fig9_mechanism.pdf",
            data=FIGURE_DATA_PATTERN.format(fig="fig9_mechanism"),
        log:
            "logs/plot/fig9_mechanism.log",
        benchmark:
            "results/benchmarks/plot/fig9_mechanism.tsv"
        localrule: True
        conda:
            "../../envs/particle-entropy.yaml"
        resources:
            mem_mb=1000,
        params:
            cases=INPUTS.section_cases("mechanism"),
            D=config["physics"]["D"],
            t_final=config["physics"]["t_final"],
            omega=config["physics"]["omega"],
            code=script_code(SCRIPTS / "plot_fig9_mechanism.py"),
        script:
            "../scripts/plot_fig9_mechanism.py"

    rule mechanism_floors:
        """The mechanism models on evenly spaced particles: SSE floors without sampling noise."""
        output:
            "results/tables/mechanism/floors.parquet",
        log:
            "logs/mechanism_floors.log",
        benchmark:
            "results/benchmarks/mechanism_floors/all.tsv"
        conda:
            "../../envs/particle-entropy.yaml"
        params:
            runs=[{"case": c.wildcards(), "settings": run_settings(c, config)} for c in lattice_cases(CONFIG)],
            times=config["comic_times"],
            code=script_code(SCRIPTS / "mechanism_floors.py"),
        script:
            "../scripts/mechanism_floors.py"
