"""The test levels the diagnosis pages state are the ones the code uses.

The doc-example runner checks code blocks; numbers in prose are checked here:
docs/diagnose.md and the docstrings of `fepost.diagnose.selection` and
`fepost.diagnose.pairs` state the Bonferroni levels as "0.05/k" and "0.01/k",
and k must be the count the code divides by, which grows with the vocabulary.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from fepost.diagnose import pairs, selection
from fepost.diagnose.causenames import CAUSES
from fepost.diagnose.causes import EXTENSIONS
from fepost.diagnose.lackfit import LOF_LEVEL

REPO = Path(__file__).resolve().parents[1]
WORDS = {"six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10, "eleven": 11, "twelve": 12}


def _levels(text: str, family: str) -> list[int]:
    return [int(k) for k in re.findall(rf"{re.escape(family)}/(\d+)", text)]


@pytest.mark.parametrize(
    "source",
    [REPO / "docs" / "diagnose.md", Path(selection.__file__), Path(pairs.__file__)],
    ids=["diagnose.md", "selection.py", "pairs.py"],
)
def test_stated_levels_match_the_code(source):
    text = source.read_text(encoding="utf-8")
    single, pair = _levels(text, "0.05"), _levels(text, "0.01")
    assert single or pair, f"{source.name} states no level"
    assert selection.ALPHA == pytest.approx(0.05 / (len(CAUSES) - 1))
    assert pairs.PAIR_ALPHA == pytest.approx(0.01 / len(EXTENSIONS))
    for k in single:
        assert 0.05 / k == pytest.approx(selection.ALPHA), f"{source.name}: 0.05/{k}"
    for k in pair:
        assert 0.01 / k == pytest.approx(pairs.PAIR_ALPHA), f"{source.name}: 0.01/{k}"


def test_the_counts_in_words_beside_the_levels():
    """ "0.05/10 (Bonferroni over the ten candidates ...)": the word is the number."""
    text = (REPO / "docs" / "diagnose.md").read_text(encoding="utf-8")
    found = re.findall(r"0\.0[15]/(\d+)\s*\(Bonferroni over the (\w+)", text.replace("\n", " "))
    assert len(found) == 2, found
    for k, word in found:
        assert WORDS[word] == int(k), (k, word)


def test_lack_of_fit_level_is_the_documented_one():
    text = (REPO / "docs" / "diagnose.md").read_text(encoding="utf-8")
    assert f"`level` ({LOF_LEVEL:g})" in text
