"""How many coarse vertices a multiresolution solve uses: ``off``, ``N``, ``P%`` or auto."""
import re

from ...runtime.numbers import digits_value

# auto: coarse-to-fine (refine mode) on AUTO_SIZE coarse vertices from AUTO_THRESHOLD
# vertices on. Measured against the direct solve (default settings, tol 1e-6, setup plus
# solve): Spot 11.5k 2.2 s either way; a cylinder Loop-subdivided once (19k) 8.7 s direct,
# 6.2 s coarse-to-fine; Spot 46k 26.0 against 13.0 s; the cylinder subdivided twice (77k)
# 66 against 29 s; the stopped shapes 3e-5 to 5e-4 of the diagonal apart. Below the
# threshold the simplification costs about what it saves.
AUTO_THRESHOLD = 20_000
AUTO_SIZE = 5_000
# ... and on at least 1/AUTO_RATIO of the mesh: the coarse-grid corrections of the
# full-resolution iterations (:mod:`.correction`) lose their grip when the coarse mesh is
# far coarser. A coarse mesh above AUTO_THRESHOLD is solved through a coarser one again.
# Full-resolution iterations to the stop (tol 1e-6) and their seconds, 1/32 against 1/8:
# 738k Spot 36, 116 s -> 21, 72 s (coarse 23k -> 92k, its coarse solve 1.9 -> 7.6 s,
# simplification the same 30 s); 184k Spot 34, 19.3 s -> 19, 16.0 s; 100k bar 31 -> 23,
# 8.6 s either way; 46k Spot (5,000 -> 5,765 coarse vertices) 25 -> 27, 4.1 -> 4.5 s.
AUTO_RATIO = 8
MIN_SIZE = 4


def parse_size(text: object) -> int | float | str:
    """Validate a multires setting: ``"off"``, ``"auto"``, an int >= 4, ``"P%"`` or a
    fraction strictly between 0 and 1 (``0.02``: what ``"2%"`` parses to).

    Returns the setting normalized (``"off"``, ``"auto"``, an int or a float fraction);
    raises ValueError with a one-line reason. Parsing is idempotent: a parsed value parses to
    itself, so a setting may pass through any number of layers (handle file, manifest,
    command line, Python keywords) unchanged.

    Examples
    --------
    >>> parse_size("2%"), parse_size("5000"), parse_size(" off "), parse_size(0.02)
    (0.02, 5000, 'off', 0.02)
    >>> parse_size(parse_size("2%")) == parse_size("0.02") == 0.02
    True
    """
    if isinstance(text, float):
        return _fraction(text)
    if isinstance(text, int) and not isinstance(text, bool):
        value = text
    else:
        s = str(text).strip().lower()
        if s in ("off", "auto"):
            return s
        if re.fullmatch(r"\d*\.\d+|\d+\.", s):
            return _fraction(float(s))
        match = re.fullmatch(r"(\d+(?:\.\d*)?)\s*%", s)
        if match:
            fraction = float(match.group(1)) / 100
            if not 0 < fraction < 1:
                raise ValueError("a percentage must be above 0% and below 100%")
            return fraction
        if not re.fullmatch(r"\d+", s):
            raise ValueError("must be off, auto, a vertex count, a percentage like 2% or a "
                             "fraction like 0.02")
        value = digits_value(s)
    if value < MIN_SIZE:
        raise ValueError(f"a coarse vertex count must be at least {MIN_SIZE}")
    return value


def _fraction(value):
    if not 0 < value < 1:
        raise ValueError("a fraction of the vertices must be above 0 and below 1 "
                         "(a vertex count is a whole number)")
    return float(value)


def coarse_size(setting: int | float | str | None, n: int) -> int | None:
    """Coarse vertex count for a mesh of ``n`` vertices, or None for a direct solve."""
    if setting is None or setting == "auto":
        return max(AUTO_SIZE, n // AUTO_RATIO) if n >= AUTO_THRESHOLD else None
    if setting == "off":
        return None
    size = max(MIN_SIZE, round(setting * n)) if isinstance(setting, float) else int(setting)
    return size if size < n else None
