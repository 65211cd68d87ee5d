"""What joins the library to the workflow: config sections to cases and paths (`sweeps`), the
typed config (`config`: a pydantic model per section, derived from core/settings.py), the
config's checks (`configcheck`: YAML, and `validate_config`, which returns the typed config;
`crosschecks`: the rules between sections and runs), memory estimates of jobs (`memory`), what
the rules read from the config (`inputs`), table verification before a run (`verify`) and the
checks while the Snakefile is read (`preflight`), one run at a time in a results folder
(`runlock`), content hashes of the code each rule runs (`codeversion`), the generated schema,
settings table and column page (`schemagen`, `columnsdoc`), the numbers the README and docs quote
(`prose`), the report's table pages (`htmlpage`) and, after a failed run, the failed jobs' logs
that Snakemake's report did not show (`joblogs`). The top of the stack with `cli`."""
