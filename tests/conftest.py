"""Shared fixtures: the real-mesh corpus beside the repository, and helpers."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"
SAMPLES = ROOT / "samples"


def corpus_files():
    """Corpus meshes, or one skipped parameter saying why there are none."""
    if not CORPUS.is_dir():
        return [pytest.param(None, marks=pytest.mark.skip(reason=f"corpus folder {CORPUS} is absent"))]
    files = sorted(p for p in CORPUS.iterdir() if p.suffix in (".obj", ".off"))
    return [pytest.param(p, id=p.name) for p in files]
