"""What joins the library to the workflow: config sections to cases and paths (`sweeps`), the
config's checks (`configcheck`: YAML and schema; `crosschecks`: the rules between fields), memory
estimates of jobs (`memory`), what the rules read from the config (`inputs`), table verification
before a run (`verify`) and the checks while the Snakefile is read (`preflight`), one run at a time
in a results folder (`runlock`), content hashes of the code each rule runs (`codeversion`), the
generated schema entries and column page (`schemagen`, `columnsdoc`), the numbers the README and
docs quote (`prose`), the report's table pages (`htmlpage`) and, after a failed run, the failed
jobs' logs that Snakemake's report did not show (`joblogs`). The top of the stack with `cli`."""
