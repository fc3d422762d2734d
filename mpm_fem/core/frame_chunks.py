"""Reuse of CPython's freed frame-stack chunks while numba compiles (CPython 3.11 and 3.12).

CPython 3.11 keeps the frames of Python calls on a stack of 16 KiB chunks, each mapped with
``mmap`` and unmapped with ``munmap`` as soon as the stack pops below it. A call that crosses a
chunk's start inside a loop maps and unmaps a chunk on every iteration (CPython issue gh-142183,
fixed in 3.13 and later by keeping one freed chunk). numba's compiler recurses deeply and does
exactly that: one compiled variant of the fused loop made about 37,000 ``mmap``/``munmap`` pairs of
16 KiB (``strace``), and those system calls and the page faults after them were most of the system
time of a cold test run (a third of its CPU time on a 2-core VM).

:func:`install` puts a small cache in front of CPython's arena allocator (``PyObject_SetArenaAllocator``,
the allocator of the frame chunks and of obmalloc's arenas): up to ``SLOTS`` freed blocks of exactly
``CHUNK`` bytes are kept and handed out again; every other size, and any block past the cache, goes
to the allocator it replaced. The two functions are 40 lines of LLVM IR compiled with llvmlite
(numba's own dependency) at install, a few milliseconds: a C callback written in Python could not
run inside the interpreter's frame push. Nothing else changes: the same memory is mapped the same
way, only reused. A no-op on interpreters without the problem (``NEEDED``) and where the
environment sets ``MPM_FEM_FRAME_CHUNKS=0``. The modules that compile (:mod:`mpm_fem.fused.step`,
:mod:`mpm_fem.exact_stages.kernels`) install it on import.
"""

from __future__ import annotations

import atexit
import ctypes
import os
import platform
import sys

CHUNK = 16 * 1024  # CPython's DATA_STACK_CHUNK_SIZE
SLOTS = 16  # freed chunks kept: 256 KiB at most
NEEDED = platform.python_implementation() == "CPython" and sys.version_info[:2] in ((3, 11), (3, 12))

# state (uint64): [replaced ctx, replaced alloc, replaced free, chunks kept, reuses, kept chunk 0 .. SLOTS-1]
_CTX, _ALLOC, _FREE, _KEPT, _REUSED, _FIRST = range(6)


def _load(name: str, index: int) -> str:
    """LLVM IR: ``%name = state[index]``."""
    return f"  %{name}_at = getelementptr i64, i64* %state, i64 {index}\n  %{name} = load i64, i64* %{name}_at\n"


def _replaced(function: str, signature: str) -> str:
    """LLVM IR: the tail call of the replaced allocator's ``function`` (``alloc`` or ``free``)."""
    index = _ALLOC if function == "alloc" else _FREE
    return (_load("ctx", _CTX) + "  %ctx_pointer = inttoptr i64 %ctx to i8*\n" + _load(function, index)
            + f"  %{function}_function = inttoptr i64 %{function} to {signature}*\n")


# chunk_alloc(state, size): a kept chunk if size == CHUNK and one is kept, else the replaced alloc;
# chunk_free(state, pointer, size): kept if size == CHUNK and there is room, else the replaced free
_IR = f"""
define i8* @chunk_alloc(i64* %state, i64 %size) {{
entry:
  %chunk = icmp eq i64 %size, {CHUNK}
  br i1 %chunk, label %check, label %replaced
check:
{_load("kept", _KEPT)}  %some = icmp sgt i64 %kept, 0
  br i1 %some, label %reuse, label %replaced
reuse:
  %last = sub i64 %kept, 1
  store i64 %last, i64* %kept_at
{_load("reused", _REUSED)}  %reused1 = add i64 %reused, 1
  store i64 %reused1, i64* %reused_at
  %slot = add i64 %last, {_FIRST}
  %slot_at = getelementptr i64, i64* %state, i64 %slot
  %block = load i64, i64* %slot_at
  %pointer = inttoptr i64 %block to i8*
  ret i8* %pointer
replaced:
{_replaced("alloc", "i8* (i8*, i64)")}  %new = call i8* %alloc_function(i8* %ctx_pointer, i64 %size)
  ret i8* %new
}}

define void @chunk_free(i64* %state, i8* %pointer, i64 %size) {{
entry:
  %chunk = icmp eq i64 %size, {CHUNK}
  br i1 %chunk, label %check, label %replaced
check:
{_load("kept", _KEPT)}  %room = icmp slt i64 %kept, {SLOTS}
  br i1 %room, label %keep, label %replaced
keep:
  %slot = add i64 %kept, {_FIRST}
  %slot_at = getelementptr i64, i64* %state, i64 %slot
  %block = ptrtoint i8* %pointer to i64
  store i64 %block, i64* %slot_at
  %kept1 = add i64 %kept, 1
  store i64 %kept1, i64* %kept_at
  ret void
replaced:
{_replaced("free", "void (i8*, i8*, i64)")}  call void %free_function(i8* %ctx_pointer, i8* %pointer, i64 %size)
  ret void
}}
"""


class _ArenaAllocator(ctypes.Structure):
    """CPython's ``PyObjectArenaAllocator``: ``ctx``, ``alloc(ctx, size)``, ``free(ctx, ptr, size)``."""
    _fields_ = [("ctx", ctypes.c_void_p), ("alloc", ctypes.c_void_p), ("free", ctypes.c_void_p)]


_installed: dict = {}  # the compiled functions, the state and the replaced allocator, kept alive
_retired: list = []  # those of an uninstalled cache: a chunk it handed out may still be in use


def installed() -> bool:
    """Whether the cache is in place."""
    return bool(_installed)


def reused() -> int:
    """How many chunks the cache has handed out again since :func:`install`."""
    return int(_installed["state"][_REUSED]) if _installed else 0


def install() -> bool:
    """Put the chunk cache in front of the arena allocator (once per process; only where
    ``NEEDED``, unless ``MPM_FEM_FRAME_CHUNKS=0``, and only if llvmlite compiles it: otherwise
    nothing changes). Returns whether it is in place. The replaced allocator is put back at exit,
    before the interpreter tears down, and the compiled code is never freed."""
    if _installed or not NEEDED or os.environ.get("MPM_FEM_FRAME_CHUNKS", "1") == "0":
        return installed()
    try:  # an optimisation only: without llvmlite's JIT the interpreter keeps its own allocator
        import llvmlite.binding as llvm

        llvm.initialize_native_target()
        llvm.initialize_native_asmprinter()
        module = llvm.parse_assembly(_IR)
        module.verify()
        engine = llvm.create_mcjit_compiler(module, llvm.Target.from_default_triple().create_target_machine())
        engine.finalize_object()
        functions = engine.get_function_address("chunk_alloc"), engine.get_function_address("chunk_free")
    except Exception:  # noqa: BLE001 - any failure leaves the interpreter as it was
        return False
    if not all(functions):
        return False
    replaced = _ArenaAllocator()
    ctypes.pythonapi.PyObject_GetArenaAllocator(ctypes.byref(replaced))
    state = (ctypes.c_uint64 * (_FIRST + SLOTS))()
    state[_CTX], state[_ALLOC], state[_FREE] = replaced.ctx or 0, replaced.alloc, replaced.free
    cache = _ArenaAllocator(ctypes.addressof(state), *functions)
    _installed.update(engine=engine, module=module, state=state, replaced=replaced, cache=cache)
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(engine))  # never freed: a chunk may be freed through it late
    ctypes.pythonapi.PyObject_SetArenaAllocator(ctypes.byref(cache))
    atexit.register(uninstall)
    return True


def uninstall() -> None:
    """Put the replaced allocator back (the kept chunks stay mapped until the process ends; the
    compiled code and the state stay alive)."""
    if _installed:
        ctypes.pythonapi.PyObject_SetArenaAllocator(ctypes.byref(_installed["replaced"]))
        _retired.append(dict(_installed))
        _installed.clear()
