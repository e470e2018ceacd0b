"""How many generated examples a run draws: the quick loop (``-m "not slow"``) fewer, the
whole suite the full count. Hypothesis tests without their own count take the profile;
those that scale theirs read SRARAP_FUZZ_EXAMPLES / SRARAP_EDGE_EXAMPLES (set here before
their modules are imported, in each xdist worker too). A value already in the environment
wins."""
import os

from hypothesis import settings

QUICK = {"SRARAP_FUZZ_EXAMPLES": "20", "SRARAP_EDGE_EXAMPLES": "16"}

settings.register_profile("quick", max_examples=25, deadline=None)
settings.register_profile("full", deadline=None)


def pytest_configure(config):
    quick = (config.getoption("markexpr", "") or "").replace(" ", "") == "notslow"
    if quick:
        for name, value in QUICK.items():
            os.environ.setdefault(name, value)
    settings.load_profile(os.environ.get("SRARAP_HYPOTHESIS_PROFILE",
                                         "quick" if quick else "full"))
