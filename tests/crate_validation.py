"""The RO-Crate validator (roc-validator) run offline on a crate: its REQUIRED checks of the
Provenance Run Crate profile (and the profiles it builds on: Workflow Run Crate, Process Run Crate,
Workflow RO-Crate, RO-Crate 1.1).

The validator fetches the crate's JSON-LD context (https://w3id.org/ro/crate/1.1/context) over
HTTP; the test machines reach only package registries. The context is the published RO-Crate 1.1
document, kept in tests/data/ro-crate-1.1-context.jsonld (as the rocrate 0.9 package shipped it);
every other request fails, so a check that needs the network fails rather than passes.
"""

from __future__ import annotations

import json
from pathlib import Path

from conftest import ROOT

PROFILE = "provenance-run-crate-0.5"
CONTEXTS = {"https://w3id.org/ro/crate/1.1/context": ROOT / "tests" / "data" / "ro-crate-1.1-context.jsonld"}


def validate_crate(folder: Path) -> list[str]:
    """The validator's REQUIRED issues of the crate in ``folder`` ([] when it conforms)."""
    import requests
    from rdflib.plugins.shared.jsonld import context as jsonld_context
    from rocrate_validator import models, services

    def send(session, request, **kwargs):
        path = CONTEXTS.get(request.url.rstrip("/"))
        if path is None:
            raise requests.ConnectionError(f"offline test: {request.url}")
        response = requests.Response()
        response.status_code, response.url, response.request = 200, request.url, request
        response.headers["Content-Type"] = "application/ld+json"
        response._content = path.read_bytes()
        return response

    loader = jsonld_context.source_to_json

    def source_to_json(source, *args, **kwargs):
        path = CONTEXTS.get(str(source).rstrip("/"))
        return (json.loads(path.read_bytes()), None) if path else loader(source, *args, **kwargs)

    original = requests.Session.send
    requests.Session.send, jsonld_context.source_to_json = send, source_to_json
    try:
        settings = services.ValidationSettings(
            rocrate_uri=str(folder),
            profile_identifier=PROFILE,
            requirement_severity=models.Severity.REQUIRED,
            skip_availability_check=True,
            no_cache=True,
        )
        result = services.validate(settings)
    finally:
        requests.Session.send, jsonld_context.source_to_json = original, loader
    return [f"{issue.check.identifier}: {issue.message}" for issue in result.get_issues()]
