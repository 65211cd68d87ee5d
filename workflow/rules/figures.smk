# One rule per figure: tables in, figures/figNN.png and .pdf out. Restyling reruns no simulation.

for _fig in ALL_FIGURES:

    rule:
        name:
            f"plot_{_fig}"
        input:
            figure_inputs(_fig),
        output:
            png=report(f"figures/{_fig}.png", caption=f"../report/{_fig}.rst", category="Figures"),
            pdf=f"figures/{_fig}.pdf",
        log:
            f"logs/plot/{_fig}.log",
        params:
            fig=_fig,
            D=config["physics"]["D"],
            t_final=config["physics"]["t_final"],
        resources:
            mem_mb=1000,
        conda:
            "../../envs/particle-entropy.yaml"
        script:
            "../scripts/plot_figure.py"


rule plot_tradeoff:
    input:
        "results/tables/tradeoff.parquet",
    output:
        png=report("figures/tradeoff.png", caption="../report/tradeoff.rst", category="Speed and accuracy"),
        pdf="figures/tradeoff.pdf",
    log:
        "logs/plot/tradeoff.log",
    conda:
        "../../envs/particle-entropy.yaml"
    script:
        "../scripts/plot_tradeoff.py"
