# Scenes (config `scenes`, scenes/scene.py): for each, the cheapest candidate model that
# reaches the stated accuracy, and the COMIC-best (analysis/scene_search.py). Each round of a scene's
# search is a checkpoint whose plan names the runs to make next; every run is an ordinary job.
# Their own target: `snakemake -j2 scenes`.


# A scene's runs: conservative (kind `runs`), or with its reaction after every transport step (kind
# `reactive`, models/simulate.py), judged against the scene's reference. One rule, the paper's script.
rule simulate_scene:
    input:
        reference=lambda w: SCENES.reference_path(w.scene_id) if w.kind == "reactive" else [],
    output:
        SCENE_RUN_PATTERN,
    log:
        f"logs/scenes/{{scene_id}}/{{kind}}/{CASE_DIR}/seeds~{{first}}-{{last}}.log",
    benchmark:
        f"results/benchmarks/simulate_scene/{{scene_id}}/{{kind}}/{CASE_DIR}/seeds~{{first}}-{{last}}.tsv"
    wildcard_constraints:
        scene_id=r"[0-9a-f]{12}",
        kind="runs|reactive",
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        settings=lambda w: SCENES.settings(w.scene_id),
        code=lambda w: SIM_CODE[w.method],
    script:
        "../scripts/simulate.py"


# A reactive scene's reference (scenes/reference.py), once per physics: the closed form of a
# decay, or A + B -> C on three fine grids in the frame moving with v, Richardson-extrapolated.
rule scene_reference:
    output:
        REFERENCE_PATTERN,
    log:
        "logs/scenes/references/{digest}.log",
    benchmark:
        "results/benchmarks/scene_reference/{digest}.tsv"
    wildcard_constraints:
        digest=r"[0-9a-f]{12}",
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        physics=lambda w: SCENES.reference_physics(w.digest),
        code=script_code(SCRIPTS / "scene_reference.py"),
    script:
        "../scripts/scene_reference.py"


checkpoint scene_round:
    input:
        unpack(scene_round_inputs),
    output:
        plan="results/scenes/{name}/round~{k}.parquet",
        read=read_path("results/scenes/{name}/round~{k}.parquet"),
    log:
        "logs/scenes/{name}/round~{k}.log",
    wildcard_constraints:
        name=SCENE_NAME,
        k=r"\d+",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        spec=lambda w: SCENES.spec(w.name),
        case_defaults=config.get("case_defaults", {}),
        base_seed=config["base_seed"],
        code=script_code(SCRIPTS / "scene_round.py"),
    script:
        "../scripts/scene_round.py"


rule scene_table:
    input:
        unpack(scene_table_inputs),
    output:
        "results/scenes/{name}.parquet",
    log:
        "logs/scenes/{name}.log",
    wildcard_constraints:
        name=SCENE_NAME,
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        spec=lambda w: SCENES.spec(w.name),
        case_defaults=config.get("case_defaults", {}),
        code=script_code(SCRIPTS / "scene_table.py"),
    script:
        "../scripts/scene_table.py"


rule plot_scene:
    input:
        "results/scenes/{name}.parquet",
    output:
        png=report(
            "figures/scene_{name}.png",
            caption="../report/scene.rst",
            category=FIGURE["scene"].category,
            labels=figure_labels("scene_{name}", "plot_scene", "results/scenes/{name}.parquet", "scene"),
        ),
        pdf="figures/scene_{name}.pdf",
    log:
        "logs/plot/scene_{name}.log",
    wildcard_constraints:
        name=SCENE_NAME,
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    resources:
        mem_mb=1000,
    params:
        spec=lambda w: SCENES.spec(w.name),  # a 2-D scene's maps run its model once (figures/scene_maps.py)
        case_defaults=config.get("case_defaults", {}),
        base_seed=config["base_seed"],
        code=script_code(SCRIPTS / "plot_scene.py"),
    script:
        "../scripts/plot_scene.py"


# Where particles overtake grids: the Peclet sweeps' scenes (peclet-<k> and peclet2d-<k>, names no
# user scene has) side by side (config `scenes_peclet`, `scenes_peclet2d`); its data beside no scene's table.
rule plot_scenes_peclet:
    input:
        [f"results/scenes/{name}.parquet" for name in SCENES.sweep],
    output:
        png=report(
            "figures/scenes_peclet.png",
            caption="../report/scenes_peclet.rst",
            category=FIGURE["scene"].category,
            labels=figure_labels("scenes_peclet", "plot_scenes_peclet", "results/scenes_peclet.parquet"),
        ),
        pdf="figures/scenes_peclet.pdf",
        data="results/scenes_peclet.parquet",
    log:
        "logs/plot/scenes_peclet.log",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    resources:
        mem_mb=1000,
    params:
        code=script_code(SCRIPTS / "plot_scenes_peclet.py"),
    script:
        "../scripts/plot_scenes_peclet.py"


# The numbers the README and docs/scenes.md quote from the scene tables (pipeline/prose.py):
# docs/numbers.json is this file of a finished paper run, and `prose --check` holds the pages to it.
rule scene_numbers:
    input:
        expand("results/scenes/{name}.parquet", name=SCENES),
    output:
        "results/scenes_numbers.json",
    log:
        "logs/scenes/numbers.log",
    localrule: True
    conda:
        "../../envs/particle-entropy.yaml"
    params:
        code=script_code(SCRIPTS / "scene_numbers.py"),
    script:
        "../scripts/scene_numbers.py"


# Every configured scene: `snakemake -j2 scenes` (not part of the default target).
rule scenes:
    input:
        expand("figures/scene_{name}.png", name=SCENES),
        ["figures/scenes_peclet.png"] if has_sweep(config) else [],
        "results/scenes_numbers.json",
        scene_files_set_aside,  # set aside before this run (pipeline/preflight.py): rebuilt now
