"""What of a run's settings its outputs depend on: what a fingerprint hashes (a batch job's
record, an animation's resume state), so that a rerun that changes only the rest is up to
date (a batch judges its recorded warnings under the rerun's strictness instead)."""
from collections.abc import Mapping
from typing import Any

#: settings that do not change what a job writes: the thread count (byte-identical outputs),
#: and the strictness that judges its warnings (``strict``, ``allow``: a rerun that changes
#: only them judges the recorded warnings again, it never solves again)
NOT_DECIDING = ("threads", "strict", "allow")


def deciding(settings: Mapping[str, Any]) -> dict[str, Any]:
    """``settings`` less those that do not change the outputs (:data:`NOT_DECIDING`): what
    a fingerprint hashes, so that a rerun with another thread count or strictness is up to
    date."""
    return {k: v for k, v in settings.items() if k not in NOT_DECIDING}
