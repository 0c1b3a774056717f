"""Identity of the solver's code (a hash of its sources) and the numba cache keyed on it.

Numba's on-disk cache checks only the source file of the function it compiled, not the
helpers inlined into it from other modules (``kernel.grad_factor`` inside the pair loop of
``forces``). Editing such a helper could then load stale machine code. So every solver
process caches its kernels in a directory named by the hash of all solver sources:
``$SPH_SURGE_CACHE_DIR/numba-<hash>`` (default base ``$XDG_CACHE_HOME/sph-surge``, else
``~/.cache/sph-surge``). Any change to any solver file compiles afresh.
"""
from __future__ import annotations

import functools
import hashlib
import os
import sys
from pathlib import Path


def files_hash(files, names: bool = True) -> str:
    """sha256 (16 hex digits) of the files' contents in the given order, each preceded by
    its file name when ``names``."""
    h = hashlib.sha256()
    for f in map(Path, files):
        h.update((f.name.encode() if names else b"") + f.read_bytes())
    return h.hexdigest()[:16]


@functools.cache
def source_hash() -> str:
    """``files_hash`` of every solver/*.py file, names and contents."""
    return files_hash(sorted(Path(__file__).parent.glob("*.py")))


def variant_named(fn, variant):
    """``fn`` renamed after ``variant`` (its compile-time switches), before numba compiles it.
    Numba keeps one cache index per function name and line; variants compiled from one
    factory would share it, and two processes adding different variants at once can give
    both the same data file, so that one later loads the other's machine code. A name per
    variant gives each its own index."""
    tag = hashlib.sha256(repr(variant).encode()).hexdigest()[:12]
    fn.__qualname__ = f"{fn.__qualname__}_{tag}"
    return fn


def cache_base() -> Path:
    base = os.environ.get("SPH_SURGE_CACHE_DIR")
    if base:
        return Path(base).resolve()
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "sph-surge"


def numba_cache_dir() -> Path:
    """Where this solver's compiled kernels live: one directory per source hash."""
    return cache_base() / f"numba-{source_hash()}"


def use_keyed_numba_cache() -> Path:
    """Point numba's cache at ``numba_cache_dir()``; must run before any kernel is defined.
    A NUMBA_CACHE_DIR set by the user is replaced: it would not be keyed on the sources."""
    path = str(numba_cache_dir())
    os.environ["NUMBA_CACHE_DIR"] = path
    if "numba" in sys.modules:  # already imported: its config has read the environment
        sys.modules["numba"].config.CACHE_DIR = path
    return Path(path)
