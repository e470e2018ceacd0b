"""The handle file's JSON Schema: published as the parser builds it, accepts every shipped
handle file, and refuses what the parser refuses where a schema can say it. The new keys
(several boxes or spheres, angle_deg/angle_rad, quaternion_wxyz/xyzw) parse to the same
targets as their old spellings."""
import glob
import os

import jsonschema
import numpy as np
import pytest
import yaml
from helpers import ROOT

from srarap_cli.io.handles import parse_handles
from srarap_cli.io.handles.schema import handle_schema, schema_text
from srarap_cli.runtime.errors import InputError

V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5], [1, 1, 0]])


def test_the_published_schema_is_the_one_the_code_builds():
    path = os.path.join(ROOT, "docs", "handles.schema.json")
    assert open(path).read() == schema_text()
    jsonschema.Draft202012Validator.check_schema(handle_schema())


HANDLE_FILES = [p for p in sorted(glob.glob(os.path.join(ROOT, "configs", "*.yaml")))
                if "groups" in yaml.safe_load(open(p))]  # not the batch manifest


@pytest.mark.parametrize("path", HANDLE_FILES)
def test_every_shipped_handle_file_validates(path):
    jsonschema.validate(yaml.safe_load(open(path)), handle_schema())


BAD = [
    {"groups": {"g": {"indices": [0], "rotate": {"axis": [0, 0, 1], "angle": 3,
                                                  "angle_rad": 1}}}},
    {"groups": {"g": {"indices": [0], "rotate": {"axis": [0, 0, 1], "angle_deg": 3,
                                                  "quaternion": [1, 0, 0, 0]}}}},
    {"groups": {"g": {"indices": [0], "bogus": 1, "fixed": True}}},
    {"groups": {"g": {"box": [], "fixed": True}}},
    {"groups": {"g": {"sel": {"file": "x.sel", "status": ["a"]}, "fixed": True}}},
    {"groups": {}},
    {"groups": {"g": {"indices": [0], "fixed": True}}, "solver": {"tol": "small"}},
]


@pytest.mark.parametrize("doc", BAD)
def test_what_the_parser_refuses_the_schema_refuses(doc):
    with pytest.raises(InputError):
        parse_handles(doc, V)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, handle_schema())


@pytest.mark.parametrize("rotate", [
    {"axis": [0, 0, 1], "angle_deg": 30}, {"axis": [0, 0, 1], "angle_rad": np.pi / 6},
    {"quaternion_wxyz": [np.cos(np.pi / 12), 0, 0, np.sin(np.pi / 12)]},
    {"quaternion_xyzw": [0, 0, np.sin(np.pi / 12), np.cos(np.pi / 12)]},
    {"quaternion": [np.cos(np.pi / 12), 0, 0, np.sin(np.pi / 12)]},
])
def test_every_rotation_spelling_gives_the_same_targets(rotate):
    def targets(rot):
        doc = {"groups": {"g": {"indices": [1, 2], "rotate": rot, "pivot": [0, 0, 0]}}}
        jsonschema.validate(doc, handle_schema())
        return parse_handles(doc, V).targets
    np.testing.assert_allclose(targets(rotate), targets({"axis": [0, 0, 1], "angle": 30}),
                               atol=1e-12)


def test_several_boxes_and_spheres_select_their_union():
    doc = {"groups": {"g": {"box": [{"min": [-.1, -.1, -.1], "max": [.1, .1, .1]},
                                    {"min": [4, 4, 4], "max": [6, 6, 6]}], "fixed": True},
                      "h": {"sphere": [{"center": [1, 0, 0], "radius": .1},
                                       {"center": [0, 1, 0], "radius": .1}],
                            "translate": [0, 0, 1]}}}
    jsonschema.validate(doc, handle_schema())
    c = parse_handles(doc, V)
    assert c.groups["g"].tolist() == [0, 3] and c.groups["h"].tolist() == [1, 2]


@pytest.mark.parametrize("action", ["fixed", "translate", "rotate", "matrix"])
def test_keyframes_beside_a_static_action_are_refused_by_the_schema_and_the_parser(action):
    """Issue 62: the published schema accepted ``keyframes`` with ``fixed`` (and the other
    static actions), a document the parser refuses."""
    from srarap_cli.io.handles.keys import STATIC_ACTIONS

    assert action in STATIC_ACTIONS
    value = {"fixed": True, "translate": [0, 0, 1], "rotate": {"axis": [0, 0, 1], "angle_deg": 9},
             "matrix": np.eye(4).tolist()}[action]
    doc = {"groups": {"top": {"indices": [1], action: value,
                              "keyframes": [{"frame": 0}, {"frame": 4, "translate": [0, 0, 1]}]}}}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, handle_schema())
    with pytest.raises(InputError, match=f"keyframes cannot be combined with {action}"):
        parse_handles(doc, np.zeros((4, 3)), fps=24)
    del doc["groups"]["top"][action]
    jsonschema.validate(doc, handle_schema())  # without it, both take the document
    parse_handles(doc, np.zeros((4, 3)), fps=24)
