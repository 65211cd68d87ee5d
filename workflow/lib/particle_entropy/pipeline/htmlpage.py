"""Self-contained HTML pages of tables for `snakemake --report`, which renders HTML, not Markdown."""

from __future__ import annotations

BASE_STYLE = "body{font-family:sans-serif;margin:1em;color:#222}table{border-collapse:collapse;font-size:13px}"


def page(title: str, body: str, style: str = "", heading: str | None = None) -> str:
    """An HTML page: ``title`` in the tab, ``heading`` (default the title) above ``body``, the
    shared style followed by a page's own ``style``; no timestamp, so equal tables give equal bytes."""
    return (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{title}</title>'
        f"<style>{BASE_STYLE}{style}</style></head>\n<body><h1>{heading or title}</h1>\n{body}</body></html>\n"
    )
