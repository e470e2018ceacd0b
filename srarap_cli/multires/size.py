"""How many coarse vertices a multiresolution solve uses: ``off``, ``N``, ``P%`` or auto."""
import re

# Below this many vertices the direct solve is the default: there it costs at most about 0.4 s
# per iteration (the project's per-iteration target at 100k vertices) and gives the exact
# minimum. Above it a direct solve takes hours (thousands of iterations at seconds each),
# while multiresolution finishes in minutes. AUTO_SIZE: on the README's quality table 5,000
# coarse vertices land within 0.17% of the diagonal of the direct result; 10,000 get to 0.11%
# for 5x the coarse solve time, and the full-resolution energy grows with the coarse size.
AUTO_THRESHOLD = 100_000
AUTO_SIZE = 5_000
MIN_SIZE = 4


def parse_size(text):
    """Validate a multires setting: ``"off"``, ``"auto"``, an int >= 4 or ``"P%"``.

    Returns the setting normalized (``"off"``, ``"auto"``, an int or a float fraction);
    raises ValueError with a one-line reason.

    Examples
    --------
    >>> parse_size("2%"), parse_size("5000"), parse_size(" off ")
    (0.02, 5000, 'off')
    """
    if isinstance(text, int) and not isinstance(text, bool):
        value = text
    else:
        s = str(text).strip().lower()
        if s in ("off", "auto"):
            return s
        match = re.fullmatch(r"(\d+(?:\.\d*)?)\s*%", s)
        if match:
            fraction = float(match.group(1)) / 100
            if not 0 < fraction < 1:
                raise ValueError("a percentage must be above 0% and below 100%")
            return fraction
        if not re.fullmatch(r"\d+", s):
            raise ValueError("must be off, auto, a vertex count or a percentage like 2%")
        value = int(s)
    if value < MIN_SIZE:
        raise ValueError(f"a coarse vertex count must be at least {MIN_SIZE}")
    return value


def coarse_size(setting, n):
    """Coarse vertex count for a mesh of ``n`` vertices, or None for a direct solve."""
    if setting is None or setting == "auto":
        return AUTO_SIZE if n >= AUTO_THRESHOLD else None
    if setting == "off":
        return None
    size = max(MIN_SIZE, round(setting * n)) if isinstance(setting, float) else int(setting)
    return size if size < n else None
