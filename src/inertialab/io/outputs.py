"""Transactional outputs: nothing half-written, nothing outside the target, no input
overwritten (docs/robustness.md).

A command's outputs are all or nothing:

- a **directory output** (``--out DIR``) is built in a temporary sibling
  ``.DIR.inertialab-tmp-<pid>-<random>`` and moved into place only when the command has
  finished. A directory inertialab wrote before (it holds the :data:`MARKER` file
  ``_inertialab``) or an
  empty one is replaced whole, so no stale ``models/*.json`` survive; a non-empty
  directory inertialab did not write is never deleted: the new files are moved into it
  one by one, replacing only regular files of the same name. A lock file
  ``.DIR.inertialab-lock`` beside it (``flock``, released by the kernel when a process
  dies) refuses a second run writing to the same directory at the same time.
- a **single-file output** is written to a temporary file beside it and renamed onto the
  target, which must be a regular file or absent: a directory, a device node, a FIFO or a
  socket is refused and never replaced (``--out /dev/null`` cannot turn the device into
  a CSV); a symbolic link to a regular file replaces the file it points to.
- nothing is created before the first write, which commands make after the input was
  read and validated; parent directories created for an output are removed again when
  the run fails.

The command line runs every command inside :func:`transaction`: writes are staged and
committed together when the command returns; an exception, ``SIGINT`` or ``SIGTERM``
removes every temporary file and directory. An output that resolves to one of the
run's inputs or its sidecar, an empty output name, and a previous output that cannot be
removed (a read-only directory in it) are refused before anything is replaced. Library code uses
:func:`output_dir` (``with output_dir(path) as tmp: ...``) or the atomic writers of
:mod:`inertialab.io.writers`, which join the current transaction when there is one.

Write errors (disk full, read-only file system, permission denied) become an
:class:`OutputError` (an :class:`~inertialab.errors.InputError`: exit 2) naming the path.
"""

from __future__ import annotations

import contextlib
import errno
import glob
import json
import os
import secrets
import shutil
import signal
import stat
from pathlib import Path

from inertialab import signals as _signals
from inertialab.errors import InputError, OutputError

#: The file that marks a directory as written by inertialab (and so replaceable whole).
MARKER = "_inertialab"
#: The marker's name before 0.x (a hidden file); directories holding it count as ours too.
_OLD_MARKERS = (".inertialab",)
_TMP_TAG = ".inertialab-tmp-"
_LOCK_TAG = ".inertialab-lock"
_OLD_TAG = ".inertialab-old-"
_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def output_error(exc: OSError, path) -> OutputError:
    """The one-line :class:`OutputError` for an ``OSError`` raised writing ``path``."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    hint = {errno.ENOSPC: "; free some space or choose another place",
            errno.EDQUOT: "; free some space or choose another place",
            errno.EROFS: "; choose a writable place",
            errno.EACCES: "; choose a writable place",
            errno.EPERM: "; choose a writable place"}.get(exc.errno, "")
    return OutputError(f"cannot write output ({reason}){hint}", path=path)


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _check_parents(p: Path) -> None:
    """Refuse a target whose existing ancestor is not a directory."""
    for anc in p.parents:
        try:
            st = os.stat(anc)
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise output_error(exc, anc) from None
        if not stat.S_ISDIR(st.st_mode):
            raise OutputError(f"'{anc}' is {_kind(st.st_mode)}, not a directory", path=p)
        return


def _given(path) -> str:
    """``path`` as text; an empty or blank output name is refused (``Path('')`` is the
    current directory, so ``--out ''`` would replace whatever the user stands in)."""
    text = os.fspath(path) if isinstance(path, os.PathLike) else str(path)
    if not text.strip():
        raise OutputError("output path is empty; name a file or directory", path=repr(text))
    return text


def file_target(path) -> Path:
    """The path a single-file output will replace: ``path`` itself, or the regular file a
    symbolic link points to. Refuses directories, devices, FIFOs, sockets, dangling links
    and an empty name (:class:`OutputError`); never creates anything."""
    p = Path(os.path.abspath(_given(path)))
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        _check_parents(p)
        return p
    except OSError as exc:
        raise output_error(exc, p) from None
    if stat.S_ISLNK(st.st_mode):
        try:
            st = os.stat(p)
        except OSError:
            raise OutputError("is a symbolic link to nothing; an output replaces only a "
                              "regular file", path=p) from None
        if stat.S_ISREG(st.st_mode):
            return Path(os.path.realpath(p))
    if stat.S_ISREG(st.st_mode):
        return p
    raise OutputError(f"is {_kind(st.st_mode)}; a file output replaces only a regular file",
                      path=p)


def dir_target(path) -> Path:
    """The directory a directory output will fill (a link to a directory is followed).
    Refuses an existing non-directory and an empty name (:class:`OutputError`); never
    creates anything."""
    p = Path(os.path.abspath(_given(path)))
    try:
        st = os.stat(p)
    except FileNotFoundError:
        if os.path.islink(p):
            raise OutputError("is a symbolic link to nothing; an output directory must be a "
                              "directory or absent", path=p) from None
        _check_parents(p)
        return p
    except OSError as exc:
        raise output_error(exc, p) from None
    if not stat.S_ISDIR(st.st_mode):
        raise OutputError(f"is {_kind(st.st_mode)}; this output is a directory", path=p)
    return Path(os.path.realpath(p))


@contextlib.contextmanager
def signals_blocked():
    """Hold SIGINT/SIGTERM back (delivered afterwards) while a commit or a clean-up
    renames files, so that an interruption never lands between two renames."""
    try:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
    except (AttributeError, ValueError, OSError):  # pragma: no cover - not POSIX
        old = None
    try:
        yield
    finally:
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _makedirs(d: Path, created: list[Path]) -> None:
    """``mkdir -p d``, recording (outermost first) the directories it created."""
    missing = []
    q = d
    while not q.exists():
        missing.append(q)
        if q.parent == q:
            break
        q = q.parent
    for m in reversed(missing):
        try:
            m.mkdir()
        except FileExistsError:
            continue
        except OSError as exc:
            raise output_error(exc, m) from None
        created.append(m)


def _remove_created(created: list[Path]) -> None:
    for d in reversed(created):
        with contextlib.suppress(OSError):
            d.rmdir()
    created.clear()


class _Lock:
    """An exclusive, non-blocking ``flock`` on ``.NAME.inertialab-lock`` beside ``target``."""

    def __init__(self, target: Path):
        import fcntl

        self.path = target.parent / f".{target.name}{_LOCK_TAG}"
        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
            except OSError as exc:
                raise output_error(exc, target) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                os.close(fd)
                raise OutputError("is being written by another inertialab run; wait for it "
                                  "to finish or choose another output", path=target) from None
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self.fd = fd
                return
            os.close(fd)  # the previous holder removed the file meanwhile: lock the new one

    def release(self) -> None:
        if self.fd is None:
            return
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        os.close(self.fd)
        self.fd = None


def _marker_text() -> str:
    from inertialab import __version__

    return json.dumps({"written_by": "inertialab", "inertialab_version": __version__,
                       "note": "inertialab replaces this directory whole when a later run "
                               "writes to it"}) + "\n"


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux ``renameat2(RENAME_EXCHANGE)``); False where the
    system cannot."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    rc = fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(b))


class _DirOutput:
    """One directory output of a transaction (built in a temporary sibling)."""

    def __init__(self, target: Path, protect: tuple[Path, ...]):
        self.target = target
        self.protect = protect
        self.staging: Path | None = None
        self.lock: _Lock | None = None
        self.created: list[Path] = []

    def materialize(self) -> Path:
        if self.staging is not None:
            return self.staging
        _makedirs(self.target.parent, self.created)
        self.lock = _RESERVED.pop(self.target, None) or _Lock(self.target)
        # any other staging directory of this target belongs to a run that died (we hold
        # the lock): remove it
        for stale in self.target.parent.glob(f".{self.target.name}{_TMP_TAG}*"):
            shutil.rmtree(stale, ignore_errors=True)
        for stale in self.target.parent.glob(f".{self.target.name}{_OLD_TAG}*"):
            shutil.rmtree(stale, ignore_errors=True)
        name = f".{self.target.name}{_TMP_TAG}{os.getpid()}-{secrets.token_hex(4)}"
        staging = self.target.parent / name
        try:
            staging.mkdir(mode=0o700)
            (staging / MARKER).write_text(_marker_text(), encoding="utf-8")
        except OSError as exc:
            shutil.rmtree(staging, ignore_errors=True)
            self.lock.release()
            raise output_error(exc, self.target) from None
        self.staging = staging
        return staging

    def _replaceable(self) -> bool:
        """The old directory may be replaced whole: it is empty, or inertialab wrote it
        and it holds none of this run's inputs."""
        try:
            entries = os.listdir(self.target)
        except FileNotFoundError:
            return True
        if not entries:
            return True
        if MARKER not in entries and not any(m in entries for m in _OLD_MARKERS):
            return False
        root = str(self.target) + os.sep
        return not any(str(p).startswith(root) for p in self.protect)

    def check_removable(self) -> None:
        """Refuse (before any work and again before the commit) to replace whole a
        previous output that cannot be removed: a read-only directory in it would leave
        the old files in an undeletable staging directory beside the new output."""
        if not self._replaceable() or not self.target.is_dir():
            return
        for root, dirs, _files in os.walk(self.target):
            if not os.access(root, os.W_OK | os.X_OK):
                raise OutputError(f"the previous output cannot be replaced: '{root}' is "
                                  "read-only; make it writable or choose another output",
                                  path=self.target)
            dirs[:] = [d for d in dirs if not os.path.islink(os.path.join(root, d))]
        if not os.access(self.target.parent, os.W_OK | os.X_OK):
            raise OutputError("cannot write output (its parent directory is read-only); "
                              "choose a writable place", path=self.target)

    def commit(self) -> None:
        if self.staging is None:
            return
        try:
            if self.target.exists() and self._replaceable():
                self.check_removable()
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(self.staging, 0o777 & ~umask)
            if not self.target.exists():
                os.rename(self.staging, self.target)
            elif self._replaceable():
                old = self.staging
                if not _exchange(self.staging, self.target):
                    old = self.target.parent / f".{self.target.name}{_OLD_TAG}{os.getpid()}"
                    os.rename(self.target, old)
                    os.rename(self.staging, self.target)
                shutil.rmtree(old, ignore_errors=True)
            else:
                self._merge()
            self.staging = None
            self.created.clear()  # the output exists now: its parents stay
        except OSError as exc:
            raise output_error(exc, self.target) from None
        finally:
            self.rollback()

    def _merge(self) -> None:
        """Move the staged files into a directory inertialab did not write (never
        deleting anything of its own); all targets are checked before the first move."""
        moves = []
        inputs = _protected_files(self.protect)
        for root, _dirs, files in os.walk(self.staging):
            rel = Path(root).relative_to(self.staging)
            for f in files:
                if rel == Path(".") and f == MARKER:
                    continue
                dest = self.target / rel / f
                file_target(dest)  # refuses a directory/device of the same name
                if os.path.realpath(dest) in inputs:
                    raise OutputError(f"output would overwrite {inputs[os.path.realpath(dest)]} "
                                      f"'{dest}'; choose another output", path=self.target)
                moves.append((Path(root) / f, dest))
        for src, dest in moves:
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(src, dest)
        shutil.rmtree(self.staging, ignore_errors=True)

    def rollback(self) -> None:
        if self.staging is not None:
            shutil.rmtree(self.staging, ignore_errors=True)
            self.staging = None
        if self.lock is not None:
            self.lock.release()
            self.lock = None
        _remove_created(self.created)


def _protected_files(paths) -> dict[str, str]:
    """Real path -> what it is, for the run's inputs and the sidecars beside them."""
    from inertialab.io.sidecar import sidecar_path

    out: dict[str, str] = {}
    for p in paths:
        with contextlib.suppress(OSError, ValueError):
            out.setdefault(os.path.realpath(sidecar_path(p)), "the sidecar of input")
            out[os.path.realpath(p)] = "input"
    return out


class Transaction:
    """The outputs of one command: staged while it runs, committed together at the end.

    Parameters
    ----------
    protect : paths
        The run's input files: a directory output is never replaced whole when it holds
        one of them (the new files are merged into it instead).
    """

    def __init__(self, protect=()):
        self.protect = tuple(Path(os.path.abspath(p)) for p in protect)
        self._inputs = _protected_files(self.protect)
        self.dirs: dict[Path, _DirOutput] = {}
        self.alias: dict[Path, Path] = {}  # the path as given (absolute) -> its target
        self.files: list[tuple[Path, Path]] = []  # (temporary, target)
        self.created: list[Path] = []

    # -- directories
    def stage_dir(self, path) -> Path:
        """Register directory output ``path`` (checked, nothing created); return the
        target directory to name in messages and to write into."""
        target = dir_target(path)
        if target not in self.dirs:
            out = _DirOutput(target, self.protect)
            out.check_removable()
            self.dirs[target] = out
        self.alias[Path(os.path.abspath(path))] = target
        return target

    def check_inside(self, path) -> None:
        """Refuse a path spelled below a staged directory output that leaves it through
        ``..`` (a name taken from data: nothing outside ``--out`` is ever created)."""
        raw = Path(os.getcwd()) / path
        norm = Path(os.path.abspath(path))
        for given in [*self.alias, *self.dirs]:
            if given in raw.parents and not (norm == given or given in norm.parents):
                raise OutputError(f"output name leads outside the output directory "
                                  f"'{given}'", path=path)

    def route(self, path) -> Path | None:
        """Where a write to ``path`` goes: its place in a staged directory (created on
        first use), or None when ``path`` is not inside a staged directory output."""
        p = Path(os.path.abspath(path))
        for given, target in [*self.alias.items(), *((t, t) for t in self.dirs)]:
            if p == given or given in p.parents:
                return self.dirs[target].materialize() / p.relative_to(given)
        return None

    # -- single files
    def refuse_input(self, target: Path, given=None) -> None:
        """Refuse an output that resolves to one of the run's input files or to an
        input's sidecar (``--out`` naming the record it reads would destroy it)."""
        real = os.path.realpath(target)
        what = self._inputs.get(real)
        if what is not None:
            raise OutputError(f"output would overwrite {what} '{real}'; choose another "
                              "output", path=given if given is not None else target)

    def stage_file(self, tmp: Path, target: Path) -> None:
        self.refuse_input(Path(target))
        self.files.append((Path(tmp), Path(target)))

    def makedirs(self, d: Path) -> None:
        _makedirs(Path(d), self.created)

    def commit(self) -> None:
        with signals_blocked():
            try:
                for _tmp, target in self.files:
                    file_target(target)  # still a regular file or absent
                for tmp, target in self.files:
                    try:
                        os.replace(tmp, target)
                    except OSError as exc:
                        raise output_error(exc, target) from None
                self.files.clear()
                self.created.clear()
                for out in self.dirs.values():
                    out.commit()
                # a signal held back during the renames now finds the outputs complete
                _signals.mark_committed()
            finally:
                self._cleanup()

    def rollback(self) -> None:
        with signals_blocked():
            self._cleanup()

    def _cleanup(self) -> None:
        for tmp, _target in self.files:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        self.files.clear()
        for out in self.dirs.values():
            out.rollback()
        _remove_created(self.created)


_CURRENT: list[Transaction] = []
#: The run's output paths named on the command line (:func:`plan`), locked when its
#: transaction starts; and those locks (target -> lock) until the transaction ends.
_PLANNED: list[str] = []
_RESERVED: dict[Path, _Lock] = {}


def check_overlap(named: list[tuple[str, str]]) -> None:
    """Refuse two outputs of one run, ``(label, path)`` each, naming the same path
    (``--export X --out X``: one would overwrite the other) or one inside the other
    (``--out D --export kalibr D/k.yaml``: D is built in a staging directory and
    replaced whole, so a file written into D beside it would be lost or leave D without
    its marker)."""
    real = [(f, t, os.path.realpath(os.path.abspath(t))) for f, t in named]
    for i, (f1, t1, r1) in enumerate(real):
        for f2, t2, r2 in real[i + 1:]:
            if r1 == r2:
                raise OutputError(f"{f1} and {f2} name the same output; give each its own "
                                  "path", path=t1)
            for fa, ta, ra, fb, tb, rb in ((f1, t1, r1, f2, t2, r2), (f2, t2, r2, f1, t1, r1)):
                if rb.startswith(ra.rstrip(os.sep) + os.sep):
                    raise OutputError(f"{fb} {tb} lies inside {fa} {ta}, which this run "
                                      f"writes as a whole; put {fb} elsewhere", path=tb)


def plan(named) -> None:
    """Name the outputs of the coming run, ``(label, path)`` each (the command line's
    ``--out``, ``--export`` ...), refused where they overlap (:func:`check_overlap`):
    its transaction locks each of them (``.NAME.inertialab-lock`` beside it) before
    the command does any work, so that a second run to the same output is refused at
    once (exit 2) while the first completes, instead of both finishing and the last
    writer winning. A path whose parent does not exist yet is locked when it is built."""
    named = list(named)
    check_overlap(named)
    _PLANNED[:] = [str(p) for _label, p in named]


def _reserve() -> None:
    try:
        for given in _PLANNED:
            target = Path(os.path.realpath(os.path.abspath(given)))
            if target in _RESERVED or not target.parent.is_dir():
                continue
            _RESERVED[target] = _Lock(target)
            # a file's temporaries left by a run that was killed (we hold the lock)
            from inertialab.io.sidecar import sidecar_path

            names = {target.name, sidecar_path(target).name}
            for stale in (p for n in names
                          for p in target.parent.glob(f".{glob.escape(n)}.*.tmp")):
                with contextlib.suppress(OSError):
                    if stale.is_file() and not stale.is_symlink():
                        stale.unlink()
    except BaseException:
        _release()
        raise


def _release() -> None:
    _PLANNED.clear()
    for lock in _RESERVED.values():
        lock.release()
    _RESERVED.clear()


def current() -> Transaction | None:
    """The innermost active :class:`Transaction`, or None."""
    return _CURRENT[-1] if _CURRENT else None


@contextlib.contextmanager
def transaction(protect=()):
    """Run a block whose outputs are committed together when it succeeds and removed
    when it raises (any exception, ``KeyboardInterrupt`` and ``SystemExit`` included).
    Inside another transaction the block joins it (the outermost one commits)."""
    if _CURRENT:  # nested: the outer transaction commits
        yield _CURRENT[-1]
        return
    _reserve()
    tx = Transaction(protect)
    _CURRENT.append(tx)
    try:
        try:
            yield tx
        except BaseException:
            _CURRENT.remove(tx)
            tx.rollback()
            raise
        _CURRENT.remove(tx)
        tx.commit()
    finally:
        _release()


@contextlib.contextmanager
def output_dir(path):
    """``with output_dir(path) as tmp:`` — write a directory output into ``tmp`` (a
    temporary sibling of ``path``); it replaces ``path`` when the block succeeds (or,
    inside a :func:`transaction`, when that commits) and vanishes when it fails."""
    outer = current()
    if outer is not None:
        target = outer.stage_dir(path)
        yield outer.route(target)
        return
    with transaction() as tx:
        target = tx.stage_dir(path)
        yield tx.route(target)


class StagedDir(type(Path())):
    """The path of a staged directory output, as :func:`stage_dir` returns it: prints as
    the final path; ``mkdir`` on it or on a path below it creates the directory in the
    staging area (so that command code calling ``(out / "models").mkdir()`` keeps
    working and creates nothing in place)."""

    def mkdir(self, mode=0o777, parents=False, exist_ok=False):
        tx = current()
        routed = tx.route(self) if tx is not None else None
        if routed is None:
            return super().mkdir(mode=mode, parents=parents, exist_ok=exist_ok)
        try:
            routed.mkdir(mode=mode, parents=True, exist_ok=True)
        except OSError as exc:
            raise output_error(exc, self) from None
        return None


def stage_dir(path) -> Path:
    """Register a directory output in the current transaction and return its final path
    (a :class:`StagedDir`); outside a transaction, create the directory now (library use,
    the old behaviour)."""
    tx = current()
    if tx is None:
        target = dir_target(path)
        try:
            target.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise output_error(exc, target) from None
        return target
    tx.stage_dir(path)
    return StagedDir(path)


def ensure_finite(values, what: str, *, path=None, allow_nan_in=None):
    """Raise :class:`~inertialab.errors.InputError` when ``values`` (an array, a
    sequence, a scalar, a pandas Series or DataFrame) holds NaN or infinity: a result
    computed from finite input must be finite, so a non-finite output is an
    error naming ``what`` (and the first offending column and row of a frame), never a
    file of NaN. ``allow_nan_in``: frame columns where NaN is a documented value.
    Returns ``values`` unchanged.
    """
    import numpy as np

    if hasattr(values, "columns"):  # DataFrame: name the column and the 1-based row
        for col in values.columns:
            if allow_nan_in and col in allow_nan_in:
                continue
            s = values[col]
            if s.dtype.kind not in "fc":
                continue
            bad = ~np.isfinite(s.to_numpy())
            if bad.any():
                row = int(np.flatnonzero(bad)[0]) + 1
                raise InputError(f"{what} is not finite ({int(bad.sum())} values); the input "
                                 "is out of the model's numeric range", path=path,
                                 column=col, row=row)
        return values
    arr = np.asarray(values.to_numpy() if hasattr(values, "to_numpy") else values)
    if arr.dtype.kind in "fc":
        bad = ~np.isfinite(arr)
        if bad.any():
            first = np.unravel_index(int(np.flatnonzero(bad.ravel())[0]), arr.shape)
            at = f" (first at index {first[0] if len(first) == 1 else tuple(map(int, first))})" \
                if arr.ndim else ""
            raise InputError(f"{what} is not finite ({int(bad.sum())} values){at}; the input "
                             "is out of the model's numeric range", path=path)
    return values


__all__ = ["MARKER", "OutputError", "StagedDir", "Transaction", "check_overlap", "current",
           "dir_target", "ensure_finite", "file_target", "output_dir", "output_error", "plan",
           "signals_blocked", "stage_dir", "transaction"]
