"""The frame-chunk cache (mpm_fem.core.frame_chunks): a call loop that crosses a chunk's start maps and
unmaps a 16 KiB chunk on every call without it (CPython 3.11, 3.12), and reuses one with it."""

import resource

import pytest

from mpm_fem.core import frame_chunks

pytestmark = pytest.mark.skipif(not frame_chunks.NEEDED, reason="this interpreter keeps a freed chunk itself")

CALLS = 20_000


def _deep(depth, calls):
    """Recurse ``depth`` frames, then make ``calls`` calls from there."""
    if depth:
        return _deep(depth - 1, calls)
    total = 0
    for _ in range(calls):
        total += _leaf()
    return total


def _leaf():
    return 1


def _faults(depth, calls):
    """Minor page faults of ``calls`` calls made ``depth`` frames down."""
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    _deep(depth, calls)
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before


def test_a_loop_across_a_chunk_start_reuses_one_chunk_instead_of_mapping_one_per_call():
    was = frame_chunks.installed()
    frame_chunks.uninstall()
    try:
        # the depth whose calls cross a chunk's start: the most faults per call without the cache
        # (each call there maps a fresh chunk and touches it); a chunk holds fewer than 400 frames here
        faults = {}
        for depth in range(400):
            faults[depth] = _faults(depth, 100)
        depth = max(faults, key=faults.get)
        without = _faults(depth, CALLS)
        assert without >= CALLS
        assert frame_chunks.install() and frame_chunks.installed()
        before = frame_chunks.reused()
        with_cache = _faults(depth, CALLS)
        assert frame_chunks.reused() - before >= CALLS - 1  # each call but the first took a kept chunk
        assert with_cache < CALLS // 100
    finally:
        frame_chunks.uninstall()
        if was:
            frame_chunks.install()


def test_the_interpreter_runs_on_with_the_cache_in_and_out():
    """Deep recursion and many objects with the cache in, then out again."""
    assert frame_chunks.install()
    assert _deep(900, 3) == 3
    assert sum(len(str(i)) for i in range(100_000)) == 488_890
    frame_chunks.uninstall()
    assert not frame_chunks.installed() and _deep(900, 3) == 3
    assert frame_chunks.install() and frame_chunks.installed()


def test_it_stays_out_when_the_environment_says_so(monkeypatch):
    was = frame_chunks.installed()
    frame_chunks.uninstall()
    monkeypatch.setenv("MPM_FEM_FRAME_CHUNKS", "0")
    try:
        assert not frame_chunks.install() and not frame_chunks.installed()
    finally:
        monkeypatch.delenv("MPM_FEM_FRAME_CHUNKS")
        if was:
            frame_chunks.install()


def test_ir_that_does_not_compile_leaves_the_allocator_alone(monkeypatch):
    was = frame_chunks.installed()
    frame_chunks.uninstall()
    monkeypatch.setattr(frame_chunks, "_IR", "define i8* @chunk_alloc(")
    try:
        assert not frame_chunks.install() and not frame_chunks.installed()
        assert _deep(300, 2) == 2
    finally:
        monkeypatch.undo()
        if was:
            frame_chunks.install()
