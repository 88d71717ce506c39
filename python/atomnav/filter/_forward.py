"""The stored forward pass of an aided-INS run, for the Rauch–Tung–Striebel smoother
(Rauch, Tung & Striebel 1965), kept in chunks of a fixed number of prediction epochs: in
memory up to a byte bound, beyond it as ``.npy`` files in a temporary directory that
are read back memory-mapped, so a record longer than memory is smoothed chunk by chunk
from its end (:meth:`atomnav.filter.AidedIns.smooth`)."""

from __future__ import annotations

import os
import tempfile
import threading

import numpy as np

#: What the core stores per epoch (``rust/filter/aided.rs``, ``ForwardPass``): Φ from
#: the previous epoch, Q_d, prior and posterior error-state mean and covariance, and the
#: nominal solution row.
FIELDS = ("phi", "qd", "x_prior", "p_prior", "x_post", "p_post", "nominal")


def epoch_bytes(n: int, n_extra: int) -> int:
    """Bytes stored per prediction epoch for ``n`` states of which ``n_extra`` in the
    sensor's extra blocks: 8 (4n² + 2n + 17 + n_extra)."""
    return 8 * (4 * n * n + 2 * n + 17 + n_extra)


class ForwardStore:
    """Chunks of ``chunk_epochs`` epochs, the first ones held in memory while they take at
    most ``memory_bytes`` in all, the later ones written to a temporary directory made
    under ``directory`` (the system's default when None) and removed with the store. The
    epochs of the chunk being filled are held in memory too. ``lock`` serialises the
    engine call and the append of its forward pass across threads. Two stores are equal
    when they hold the same epochs in the same chunks with the same settings (wherever the
    chunks are kept)."""

    __slots__ = ("chunk_epochs", "memory_bytes", "directory", "_chunks", "_pending", "_pending_epochs", "_held", "_tmp", "lock")

    def __init__(self, chunk_epochs: int, memory_bytes: int, directory: str | None):
        self.chunk_epochs = chunk_epochs
        self.memory_bytes = memory_bytes
        self.directory = directory
        self._chunks: list = []  # a dict of arrays (in memory) or the path prefix of its files
        self._pending: list[dict] = []
        self._pending_epochs = 0
        self._held = 0
        self._tmp: tempfile.TemporaryDirectory | None = None
        self.lock = threading.Lock()

    @property
    def epochs(self) -> int:
        """Epochs stored so far."""
        return sum(len(self._load(c)["phi"]) for c in self._chunks) + self._pending_epochs

    @property
    def on_disk(self) -> int:
        """Chunks written to disk."""
        return sum(isinstance(c, str) for c in self._chunks)

    def append(self, forward: tuple) -> None:
        """Add the forward pass of one engine call (the arrays of :data:`FIELDS`)."""
        part = dict(zip(FIELDS, forward))
        if not len(part["phi"]):
            return
        self._pending.append(part)
        self._pending_epochs += len(part["phi"])
        while self._pending_epochs >= self.chunk_epochs:
            whole = {f: np.concatenate([p[f] for p in self._pending]) for f in FIELDS}
            k = self.chunk_epochs
            self._keep({f: a[:k] for f, a in whole.items()})
            rest = {f: a[k:] for f, a in whole.items()}
            self._pending_epochs -= k
            self._pending = [rest] if self._pending_epochs else []

    def _keep(self, chunk: dict) -> None:
        size = sum(a.nbytes for a in chunk.values())
        if self._held + size <= self.memory_bytes:
            self._held += size
            self._chunks.append({f: np.ascontiguousarray(a) for f, a in chunk.items()})
        else:
            self._chunks.append(self._write(chunk))

    def _write(self, chunk: dict) -> str:
        if self._tmp is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="atomnav-forward-", dir=self.directory)
        prefix = os.path.join(self._tmp.name, f"chunk{len(self._chunks):08d}")
        for f, a in chunk.items():
            np.save(f"{prefix}_{f}.npy", a)
        return prefix

    @staticmethod
    def _load(chunk) -> dict:
        if isinstance(chunk, dict):
            return chunk
        return {f: np.load(f"{chunk}_{f}.npy", mmap_mode="r") for f in FIELDS}

    def chunks(self) -> list[tuple[int, dict]]:
        """(index of the first epoch, arrays) of every chunk in record order, the epochs
        of the chunk being filled last; chunks on disk are memory-mapped."""
        out, first = [], 0
        parts = [self._load(c) for c in self._chunks]
        if self._pending:
            parts.append({f: np.concatenate([p[f] for p in self._pending]) for f in FIELDS})
        for c in parts:
            out.append((first, c))
            first += len(c["phi"])
        return out

    def __eq__(self, other) -> bool:
        if not isinstance(other, ForwardStore):
            return NotImplemented
        settings = ("chunk_epochs", "memory_bytes", "directory", "_held")
        if any(getattr(self, k) != getattr(other, k) for k in settings) or len(self._chunks) != len(other._chunks):
            return False
        if [isinstance(c, str) for c in self._chunks] != [isinstance(c, str) for c in other._chunks]:
            return False
        mine, theirs = self.chunks(), other.chunks()
        return len(mine) == len(theirs) and all(np.array_equal(a[f], b[f]) for (_, a), (_, b) in zip(mine, theirs) for f in FIELDS)

    __hash__ = None

    def __getstate__(self) -> dict:
        # a copy owns its chunks: those on disk travel as arrays and are written again
        state = {k: getattr(self, k) for k in ("chunk_epochs", "memory_bytes", "directory", "_pending", "_pending_epochs", "_held")}
        state["_chunks"] = [(isinstance(c, str), {f: np.array(a) for f, a in self._load(c).items()}) for c in self._chunks]
        return state

    def __setstate__(self, state: dict) -> None:
        chunks = state.pop("_chunks")
        for k, v in state.items():
            setattr(self, k, v)
        self._chunks, self._tmp, self.lock = [], None, threading.Lock()
        for on_disk, c in chunks:
            self._chunks.append(self._write(c) if on_disk else c)
