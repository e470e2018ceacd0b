"""Keyframed handle motion: sample a group's rigid transform at any frame.

Translations are interpolated linearly or with smoothstep easing; rotations by slerp on the
shortest arc; both about the group's pivot. Before the first key the first holds, after the
last the last.
"""
from dataclasses import dataclass

import numpy as np

from ...solver.quaternion import to_matrix

EASINGS = ("linear", "smoothstep")


@dataclass
class Track:
    """Keys of one group, sorted by frame.

    Attributes
    ----------
    frames : (k,) float array, strictly increasing
    translations : (k, 3) float array
    rotations : (k, 4) float array, unit quaternions, each on the hemisphere of the one before
    pivot : (3,) float array
    easing : str, one of EASINGS
    first_only : bool, the keys given by time were left out (no frame rate): the track holds
        the pose at frame 0 only
    """

    frames: np.ndarray
    translations: np.ndarray
    rotations: np.ndarray
    pivot: np.ndarray
    easing: str = "linear"
    first_only: bool = False

    def transform(self, frame: float) -> tuple[np.ndarray, np.ndarray]:
        """Rotation matrix (3, 3) and translation (3,) at ``frame``."""
        k = int(np.searchsorted(self.frames, frame, side="right")) - 1
        if k < 0:
            return to_matrix(self.rotations[0]), self.translations[0]
        if k >= len(self.frames) - 1:
            return to_matrix(self.rotations[-1]), self.translations[-1]
        t = (frame - self.frames[k]) / (self.frames[k + 1] - self.frames[k])
        if self.easing == "smoothstep":
            t = t * t * (3 - 2 * t)
        q = slerp(self.rotations[k], self.rotations[k + 1], t)
        return to_matrix(q), (1 - t) * self.translations[k] + t * self.translations[k + 1]

    def apply(self, rest: np.ndarray, frame: float) -> np.ndarray:
        """Positions (m, 3) of the group's rest positions ``rest`` at ``frame``."""
        R, t = self.transform(frame)
        return (rest - self.pivot) @ R.T + self.pivot + t


def slerp(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    """Spherical interpolation of unit quaternions on the shortest arc.

    Examples
    --------
    >>> from srarap_cli.solver.quaternion import from_axis_angle
    >>> q = slerp(np.array([1., 0, 0, 0]), from_axis_angle([0, 0, 1], 90), 0.5)
    >>> np.allclose(q, from_axis_angle([0, 0, 1], 45))
    True
    """
    if a @ b < 0:
        b = -b
    cos = min(float(a @ b), 1.0)
    angle = np.arccos(cos)
    if angle < 1e-12:
        return a
    return (np.sin((1 - t) * angle) * a + np.sin(t * angle) * b) / np.sin(angle)
