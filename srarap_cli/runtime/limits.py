"""Refuse work that would not fit in memory, early and with an estimate."""
import os

from .errors import InputError

# Measured on this project's machines (README, "Limits"): parsing text meshes holds about 17x
# the file size; an SR solve about 4 KB per vertex on a long bar, more where the
# factorizations fill in. These carry a safety margin.
READ_FACTOR = {".obj": 20, ".off": 20, ".ply": 6, ".stl": 6}
SOLVE_BYTES_PER_VERTEX = 8_000
ENV = "SRARAP_MEMORY_LIMIT"


def available_memory():
    """Bytes srarap may plan to use: ``$SRARAP_MEMORY_LIMIT`` if set, else MemAvailable."""
    if os.environ.get(ENV):
        try:
            return int(float(os.environ[ENV]))
        except ValueError:
            raise InputError(f"{ENV}={os.environ[ENV]!r}: expected a number of bytes") from None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:  # no /proc (not Linux): ask the C library below
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def _refuse(what, need, have):
    raise InputError(f"{what} needs about {need / 1e9:.1f} GB of memory, "
                     f"{have / 1e9:.1f} GB available (set {ENV} to change the assumption)")


def check_read(path):
    """Before reading: refuse a mesh file whose parsing would not fit."""
    have = available_memory()
    if have is None or not os.path.isfile(path):
        return
    factor = READ_FACTOR.get(os.path.splitext(str(path))[1].lower(), 20)
    need = factor * os.path.getsize(path)
    if need > have:
        _refuse(f"{path}: reading it", need, have)


def check_solve(path, n_vertices):
    """Before solving: refuse a mesh whose solve would not fit."""
    have = available_memory()
    need = SOLVE_BYTES_PER_VERTEX * n_vertices
    if have is not None and need > have:
        _refuse(f"{path}: deforming its {n_vertices} vertices", need, have)
