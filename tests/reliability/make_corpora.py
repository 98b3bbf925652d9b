#!/usr/bin/env python3
"""Regenerates the committed test inputs of issue 8 (run from anywhere):

  fuzz/corpus/{hair,tfx,obj,scene}/  seed corpora of the libFuzzer targets
  data/malformed/                    the malformed-input corpus (tests/reliability)

Every file is small and deterministic. data/malformed/expected.txt lists, per
file, a fragment of the error message the CLI must print (the test fails for a
file without an entry).
"""
import json
import math
import pathlib
import shutil
import struct

ROOT = pathlib.Path(__file__).resolve().parents[2]
FUZZ = ROOT / "fuzz" / "corpus"
BAD = ROOT / "data" / "malformed"

SEGMENTS, POINTS, THICKNESS, TRANSPARENCY, COLORS = 1, 2, 4, 8, 16


def hair(strands, points, arrays, default_segments=0, magic=b"HAIR", body=b""):
    header = magic + struct.pack("<4I5f", strands, points, arrays, default_segments,
                                 1e-4, 0.0, 1.0, 1.0, 1.0) + b"\0" * 88
    assert len(header) == 128
    return header + body


def floats(values):
    return struct.pack(f"<{len(values)}f", *values)


def strand_points(strands, per, scale=0.01):
    pts = []
    for s in range(strands):
        for k in range(per):
            pts += [s * scale, k * scale, 0.5 * scale * math.sin(k + s)]
    return pts


def tfx(strands, per, positions=160, strand_uv=0, vertex_uv=0, thickness=0, color=0,
        version=4.0, body=b""):
    header = struct.pack("<f7I", version, strands, per, positions, strand_uv, vertex_uv,
                         thickness, color) + b"\0" * 128
    assert len(header) == 160
    return header + body


def write(directory, name, data):
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / name
    path.write_bytes(data if isinstance(data, bytes) else data.encode())


def ratboy_strands(count):
    """The header and the first `count` strands of data/Ratboy_mohawk.tfx."""
    raw = (ROOT / "data" / "Ratboy_mohawk.tfx").read_bytes()
    version, strands, per, off_pos = struct.unpack_from("<f3I", raw, 0)
    return per, raw[off_pos:off_pos + count * per * 16]


def seeds():
    shutil.rmtree(FUZZ, ignore_errors=True)
    # .hair: every optional array, the default segment count, an empty groom.
    pts = strand_points(2, 4)
    body = struct.pack("<2H", 3, 3) + floats(pts) + floats([1e-4] * 8) + floats([0.0] * 8) \
        + floats([0.5, 0.4, 0.3] * 8)
    write(FUZZ / "hair", "all_arrays.hair",
          hair(2, 8, SEGMENTS | POINTS | THICKNESS | TRANSPARENCY | COLORS, body=body))
    write(FUZZ / "hair", "default_segments.hair",
          hair(3, 9, POINTS, default_segments=2, body=floats(strand_points(3, 3))))
    write(FUZZ / "hair", "repeated_point.hair",
          hair(1, 4, POINTS, default_segments=3, body=floats([0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 2, 0])))
    write(FUZZ / "hair", "empty_groom.hair", hair(0, 0, POINTS))

    # .tfx: four Ratboy strands with thickness and colours; a 2x3 file with
    # UVs; the first 4 kB of Ratboy (truncated).
    per, positions = ratboy_strands(4)
    n = 4 * per
    thickness_at = 160 + len(positions)
    color_at = thickness_at + 4 * 4
    write(FUZZ / "tfx", "ratboy_4_strands.tfx",
          tfx(4, per, thickness=thickness_at, color=color_at,
              body=positions + floats([1.0, 0.8, 0.6, 0.5]) + floats([0.3, 0.2, 0.1, 1.0] * n)))
    body = b"".join(floats([s, k, 0, 1]) for s in range(2) for k in range(3))
    strand_uv_at = 160 + len(body)
    vertex_uv_at = strand_uv_at + 2 * 8
    write(FUZZ / "tfx", "small_uvs.tfx",
          tfx(2, 3, strand_uv=strand_uv_at, vertex_uv=vertex_uv_at,
              body=body + floats([0.0] * 4) + floats([0.0] * 12)))
    write(FUZZ / "tfx", "ratboy_prefix.tfx", (ROOT / "data" / "Ratboy_mohawk.tfx").read_bytes()[:4096])

    # OBJ: polylines, Blender-style edge chains, negative and i/t indices,
    # faces and other records, CRLF.
    write(FUZZ / "obj", "polylines.obj",
          "# two strands\no hair\nv 0 0 0\nv 0 1 0\nv 0 2 0\nl 1 2 3\n"
          "v 1 0 0\nv 1 1 0\nv 1 2 0\nl 4 5\nl 5 6\nv 2 0 0\nv 2 1 0\nl -2/1 -1/2\r\n"
          "vt 0 0\nvn 0 1 0\ng hair\ns off\nf 1 2 3\nusemtl hair\n")
    write(FUZZ / "obj", "blender_edges.obj",
          "".join(f"v {0.01 * k:g} {0.02 * k:g} 1.5e-3\n" for k in range(6))
          + "".join(f"l {k} {k + 1}\n" for k in range(1, 6)))

    # Scenes: the examples of data/scenes plus the features they do not use.
    for scene in sorted((ROOT / "data" / "scenes").glob("*.json")):
        write(FUZZ / "scene", scene.name, scene.read_bytes())
    exact = {
        "groom": {"file": "groom.hair"},
        "fiber": {"eta": 1.55, "alpha_R": -7.5, "beta_R": 7.5, "eccentricity": 0.9,
                  "caustic_width": 15, "caustic_gain": 0.5, "caustic_fade": 0.3,
                  "caustic_max_width": 0.5},
        "lights": [{"type": "point", "position": [0, 1, 0]}],
        "camera": {"position": [0, 0, -1], "look_at": [0, 0, 0], "up": [0, 1, 0],
                   "resolution": [16, 16]},
        "head": None,
        "grid": {"voxel_size": "auto"},
        "global_term": {"mode": "exact", "exact": {"rays": 4, "radius": 0.01}},
        "shading_rate": "vertex",
        "output": {"exr": None, "png": "x.png", "exposure": 1, "tone_map": "filmic"},
    }
    write(FUZZ / "scene", "exact_features.json", json.dumps(exact, indent=1))
    procedural = {
        "groom": {"procedural": {"style": "straight", "strands": 10, "points_per_strand": 4,
                                 "seed": 3, "length": 0.2, "length_variation": 0.1,
                                 "wave_amplitude": 0.01, "wave_length": 0.05,
                                 "clump_strength": 0.3, "head_center": [0, 0, 0],
                                 "head_radius": 0.1}},
        "lights": [],
        "camera": {"position": [0, 0, -1], "look_at": [0, 0, 0]},
    }
    write(FUZZ / "scene", "procedural_features.json", json.dumps(procedural))
    # Inputs of fixed findings (regression seeds).
    write(FUZZ / "scene", "regression_number_overflow.json", '{"background": [1e400, 0, 0]}')
    write(FUZZ / "scene", "regression_seed_2pow64.json",
          '{"groom": {"procedural": {"seed": 18446744073709551616}}, "lights": [], '
          '"camera": {"position": [0,0,-1], "look_at": [0,0,0]}}')


MINIMAL_SCENE = {
    "groom": {"procedural": {"style": "wavy", "strands": 10}},
    "lights": [{"type": "directional", "direction": [0, 1, 0]}],
    "camera": {"position": [0, 0, -1], "look_at": [0, 0, 0]},
}


def scene_with(**changes):
    scene = json.loads(json.dumps(MINIMAL_SCENE))
    for key, value in changes.items():
        scene[key] = value
    return json.dumps(scene)


def malformed():
    shutil.rmtree(BAD, ignore_errors=True)
    expected = []

    def bad(name, data, fragment):
        write(BAD, name, data)
        expected.append((name, fragment))

    valid_body = floats(strand_points(2, 3))
    bad("empty.hair", b"", "truncated header")
    bad("empty.tfx", b"", "truncated header")
    bad("empty.obj", b"", "no polylines")
    bad("empty.json", b"", "invalid JSON")
    bad("truncated_header.hair", hair(2, 6, POINTS)[:100], "truncated header")
    bad("truncated_points.hair", hair(2, 6, POINTS, 2, body=valid_body[:-5]), "truncated")
    bad("wrong_magic.hair", hair(2, 6, POINTS, 2, magic=b"HIAR", body=valid_body), "wrong magic")
    bad("unknown_bits.hair", hair(2, 6, POINTS | 64, 2, body=valid_body), "unknown array bits")
    bad("no_points_bit.hair", hair(2, 6, SEGMENTS, 2, body=valid_body), "no points array")
    bad("absurd_counts.hair", hair(0xFFFFFFFF, 0xFFFFFFFF, POINTS | SEGMENTS, body=valid_body),
        "more than the limit")
    bad("absurd_points.hair", hair(1, 0x3FFFFFFF, POINTS, 0x3FFFFFFE, body=valid_body),
        "which need")
    bad("more_strands_than_points.hair", hair(7, 6, POINTS, 0, body=valid_body),
        "every strand needs points")
    bad("segment_sum_mismatch.hair",
        hair(2, 6, POINTS | SEGMENTS, body=struct.pack("<2H", 2, 60000) + valid_body),
        "strand segment counts need")
    bad("one_point_strands.hair", hair(2, 2, POINTS, 0, body=floats([0] * 6)),
        "a strand needs at least 2")
    nan_points = strand_points(2, 3)
    nan_points[4] = float("nan")
    bad("nan_coordinate.hair", hair(2, 6, POINTS, 2, body=floats(nan_points)),
        "non-finite coordinate")
    inf_points = strand_points(2, 3)
    inf_points[9] = float("-inf")
    bad("inf_coordinate.hair", hair(2, 6, POINTS, 2, body=floats(inf_points)),
        "non-finite coordinate")
    bad("garbage_with_magic.hair", b"HAIR" + bytes((i * 37 + 11) % 256 for i in range(600)),
        ".hair")

    tfx_body = b"".join(floats([s, k, 0, 1]) for s in range(2) for k in range(3))
    bad("truncated_positions.tfx", tfx(2, 3, body=tfx_body[:40]), "truncated or corrupt")
    bad("wrong_version.tfx", tfx(2, 3, version=3.0, body=tfx_body), "not a TressFX 4 file")
    bad("nan_version.tfx", tfx(2, 3, version=float("nan"), body=tfx_body), "not a TressFX 4 file")
    bad("absurd_counts.tfx", tfx(0xFFFFFFFF, 0xFFFFFFFF, body=tfx_body), "more than the limit")
    bad("huge_offsets.tfx", tfx(2, 3, positions=0xFFFFFFF0, body=tfx_body), "truncated or corrupt")
    bad("offset_in_header.tfx", tfx(2, 3, positions=8, body=tfx_body), "inside the header")
    bad("color_past_end.tfx", tfx(2, 3, color=160 + 64, body=tfx_body), "vertex colours")
    bad("one_vertex_strands.tfx", tfx(6, 1, body=tfx_body), "at least 2")
    nan_tfx = b"".join(floats([s, k, float("nan") if k == 1 else 0, 1])
                       for s in range(2) for k in range(3))
    bad("nan_coordinate.tfx", tfx(2, 3, body=nan_tfx), "non-finite coordinate")

    bad("huge_index.obj", "v 0 0 0\nv 0 1 0\nl 1 99999999999999999999\n", "not a vertex index")
    bad("large_index.obj", "v 0 0 0\nv 0 1 0\nl 1 4294967297\n", "out of range")
    bad("negative_index.obj", "v 0 0 0\nv 0 1 0\nl -3 -1\n", "out of range")
    bad("zero_index.obj", "v 0 0 0\nv 0 1 0\nl 0 1\n", "not a vertex index")
    bad("nan_coordinate.obj", "v 0 0 0\nv 0 nan 0\nl 1 2\n", "non-finite coordinate")
    bad("overflow_coordinate.obj", "v 0 0 0\nv 0 1e39 0\nl 1 2\n", "not a number")
    bad("short_vertex.obj", "v 0 0\nl 1 2\n", "vertex needs 3 coordinates")
    bad("one_vertex_polyline.obj", "v 0 0 0\nl 1\n", "at least 2 vertices")
    bad("faces_only.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "no polylines")
    bad("nul_bytes.obj", b"v 0 0 0\nv 0 1 0\n\0l 1 2\n", "NUL bytes")
    bad("binary_garbage.obj", bytes((i * 73 + 5) % 256 or 1 for i in range(2048)), ".obj")

    bad("not_json.json", "groom = hair\n", "invalid JSON")
    bad("truncated.json", scene_with()[:-20], "invalid JSON")
    bad("deeply_nested.json", "[" * 50000 + "]" * 50000, "expected an object")
    bad("deeply_nested_key.json",
        scene_with(fiber={"a": "deep"}).replace('"deep"', '{"a":' * 20000 + "1" + "}" * 20000),
        "/fiber/a: unknown key")
    bad("deeply_nested_unterminated.json", '{"lights": ' + "[" * 100000, "invalid JSON")
    bad("wrong_type_lights.json", scene_with(lights="bright"), "/lights")
    bad("wrong_type_resolution.json",
        scene_with(camera={"position": [0, 0, -1], "look_at": [0, 0, 0],
                           "resolution": ["1024", 1024]}), "/camera/resolution/0")
    bad("huge_resolution.json",
        scene_with(camera={"position": [0, 0, -1], "look_at": [0, 0, 0],
                           "resolution": [16384, 16384]}), "pixels")
    bad("absurd_strands.json",
        scene_with(groom={"procedural": {"strands": 10000000, "points_per_strand": 4096}}),
        "/groom/procedural/strands")
    bad("huge_integer.json",
        scene_with(groom={"procedural": {"strands": 1e300}}), "/groom/procedural/strands")
    bad("nan_literal.json", scene_with(background=[float("nan"), 0, 0]),
        "invalid JSON")
    bad("overflow_number.json", scene_with(background=[0, 0, 0]).replace("[0, 0, 0]", "[1e400, 0, 0]"),
        "number overflow")
    bad("unknown_key.json", scene_with(lihgts=[]), "unknown key")
    bad("too_many_lights.json",
        scene_with(lights=[{"type": "point", "position": [0, i, 0]} for i in range(17)]), "/lights")
    bad("zero_direction.json",
        scene_with(lights=[{"type": "directional", "direction": [0, 0, 0]}]), "/lights/0/direction")
    bad("camera_inside_head.json", scene_with(head={"center": [0, 0, -1], "radius": 0.5}),
        "inside the head")
    bad("missing_groom_file.json", scene_with(groom={"file": "no_such_groom.hair"}),
        "no_such_groom.hair")
    bad("malformed_groom_file.json", scene_with(groom={"file": "nan_coordinate.hair"}),
        "non-finite coordinate")
    bad("environment_missing_file.json",
        scene_with(lights=[{"type": "environment", "file": "no_such_map.exr"}]),
        "no_such_map.exr: cannot read OpenEXR file")
    bad("environment_not_an_exr.json",
        scene_with(lights=[{"type": "environment", "file": "empty.obj"}]),
        "empty.obj: cannot read OpenEXR file")
    bad("environment_two.json",
        scene_with(lights=[{"type": "environment"}, {"type": "environment", "file": "a.exr"}]),
        "a scene has at most one")
    bad("environment_rotation.json",
        scene_with(lights=[{"type": "environment", "rotation": 1e9}]), "/lights/0/rotation")
    bad("binary_garbage.json", bytes((i * 151 + 7) % 256 for i in range(1024)), "invalid JSON")
    bad("utf16.json", scene_with().encode("utf-16"), "invalid JSON")

    expected.sort()
    (BAD / "expected.txt").write_text(
        "# The malformed-input corpus, made by tests/reliability/make_corpora.py: every file\n"
        "# must make the CLI exit with code 2 and an error containing its fragment\n"
        "# (tests/reliability/malformed_input_test.cpp). file<TAB>fragment\n"
        + "".join(f"{name}\t{fragment}\n" for name, fragment in expected))


if __name__ == "__main__":
    seeds()
    malformed()
