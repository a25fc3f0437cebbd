"""The ``Examples`` sections of the main public functions run, and print what they show.

The examples use the sample maps of the repository (``meshes/``), named as a user in a
clone would: they run with the repository as the working directory. The modules are
listed here (not ``--doctest-modules`` over the whole package) to keep the run short:
about ten seconds, most of it four analyses of the small CalculiX sample.
"""

from __future__ import annotations

import doctest
import importlib
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
#: Modules whose docstrings carry runnable examples: the pipeline, reading, the friction
#: models' evaluation and the identification.
MODULES = (
    "fepost.analysis",
    "fepost.reader",
    "fepost.friction.closed_form",
    "fepost.friction.summary",
    "fepost.friction.predict",
    "fepost.identify.fit",
)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name, monkeypatch):
    monkeypatch.chdir(REPO)
    module = importlib.import_module(name)
    tests = [t for t in doctest.DocTestFinder().find(module, name) if t.examples]
    assert tests, f"{name} has no examples"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in tests:
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, (
        f"{result.failed} of {result.attempted} examples failed in {name} (output above)"
    )


def test_the_main_functions_have_examples():
    """The entry points a user starts from each show a runnable example."""
    from fepost.analysis import analyse
    from fepost.friction.predict import predict
    from fepost.friction.summary import map_model
    from fepost.identify.fit import fit_table1
    from fepost.reader import read_contact

    for func in (analyse, read_contact, map_model, predict, fit_table1):
        doc = func.__doc__ or ""
        assert re.search(r"\n\s*Examples\n\s*-{8}\n(?:.*\n)*?\s*>>> ", doc), func.__name__
