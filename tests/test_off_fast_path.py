"""The bulk OFF reader gives exactly what the line-by-line reader gives, and leaves every file
it is not sure of (comments, colours, odd line shapes) to it."""
import numpy as np
import pytest

from srarap_cli.io.mesh import off
from srarap_cli.runtime.errors import InputError

SQUARE = ("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", True)
VARIANTS = [
    SQUARE,
    ("OFF 4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n", True),  # counts on the keyword line
    ("OFF\n4  2 0\n 0\t0 0 \n1 0 0\r\n1 1 0\n0 1 0\n3 0 1 2\n3  0 2 3\n\n\n", True),
    ("# made by hand\nOFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", False),
    ("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 255 0 0\n3 0 2 3 0 255 0\n", False),
    ("COFF\n4 2 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n1 1 0 1 1 1 1\n0 1 0 1 1 1 1\n"
     "3 0 1 2\n3 0 2 3\n", False),
    ("off\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", False),
    ("OFF\n4 2 0\n0 0 0\n\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", False),  # a blank line
]


@pytest.mark.parametrize("text, bulk", VARIANTS)
def test_bulk_and_line_by_line_agree(tmp_path, text, bulk):
    path = tmp_path / "m.off"
    path.write_text(text)
    assert (off._read_plain(text) is not None) == bulk
    fast, slow = off.read_off(str(path)), off._read_general(str(path))
    for name in ("vertices", "face_sizes", "face_vertices"):
        a, b = getattr(fast, name), getattr(slow, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name


@pytest.mark.parametrize("text", [
    "OFF\n4 1 0\n0 0\n1 0 0 0\n1 1 0\n0 1 0\n3 0 1 2\n",  # 2 + 4 numbers: still 12 in all
    "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2\n",  # says 4 corners, lists 3
    "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 x\n",
])
def test_malformed_files_get_the_line_by_line_readers_verdict(tmp_path, text):
    path = tmp_path / "bad.off"
    path.write_text(text)
    assert off._read_plain(text) is None
    with pytest.raises(InputError):
        off.read_off(str(path))


def test_a_face_past_the_vertices_is_left_to_the_checks(tmp_path):
    text = "OFF\n3 1 0\n0 0 0\n1 0 0\n1 1 0\n3 0 1 7\n"
    assert off._read_plain(text) is None
