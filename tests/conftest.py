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


@pytest.fixture(scope="session", autouse=True)
def _marker_cache(tmp_path_factory):
    """Markers sparrow finds are kept in a cache (patterns.nesting.cache_folder): the suite keeps its own,
    fresh each run, instead of the user's."""
    import os

    folder = tmp_path_factory.mktemp("marker-cache")
    old = os.environ.get("PATTERNS_CACHE")
    os.environ["PATTERNS_CACHE"] = str(folder)
    yield folder
    if old is None:
        os.environ.pop("PATTERNS_CACHE", None)
    else:
        os.environ["PATTERNS_CACHE"] = old
