"""How many generated examples a run draws: the quick loop (``-m "not slow"``) fewer, the
whole suite the full count. Hypothesis tests without their own count take the profile;
those that scale theirs read SRARAP_FUZZ_EXAMPLES / SRARAP_EDGE_EXAMPLES (set here before
their modules are imported, in each xdist worker too). A value already in the environment
wins.

Under xdist each worker's solves run its share of the CPUs (``SRARAP_THREADS``), as a batch's
workers do: two workers each running two threads on two cores contended (the suite's
quick loop 48 -> 71 s). Tests of the threads set their own counts."""
import os

from hypothesis import settings

QUICK = {"SRARAP_FUZZ_EXAMPLES": "20", "SRARAP_EDGE_EXAMPLES": "16"}

settings.register_profile("quick", max_examples=25, deadline=None)
settings.register_profile("full", deadline=None)


def pytest_configure(config):
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1") or 1)
    if workers > 1:
        from srarap_cli.runtime.parallel import available_cpus

        os.environ.setdefault("SRARAP_THREADS", str(max(1, available_cpus() // workers)))
    quick = (config.getoption("markexpr", "") or "").replace(" ", "") == "notslow"
    if quick:
        for name, value in QUICK.items():
            os.environ.setdefault(name, value)
    settings.load_profile(os.environ.get("SRARAP_HYPOTHESIS_PROFILE",
                                         "quick" if quick else "full"))
