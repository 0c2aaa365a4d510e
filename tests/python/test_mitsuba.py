"""Mitsuba 3 XML importer (python/lantern/mitsuba/): parser and BSDF-mapping units on small
inline scenes, and Bitterli's cornell-box and veach-mis rendered by Lantern against Tungsten's
references.

The reference checks print their numbers (docs/mitsuba_import.md); reproduce them with
    .venv/bin/python -m pytest -q -s tests/python/test_mitsuba.py -k "tungsten or veach"
"""
import math
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import lantern
from lantern import imageio, metrics
from lantern import mitsuba as mi

SCENES = Path("/work/shared/scenes/bitterli")


def write(tmp_path, body, name="scene.xml"):
    path = tmp_path / name
    path.write_text(f'<scene version="3.0.0">\n{body}\n</scene>\n')
    return path


def sensor_xml(to_world, fov="40", extra="", w=200, h=100, rfilter="tent"):
    return f"""
    <sensor type="perspective">
        <float name="fov" value="{fov}"/>
        {extra}
        <transform name="to_world">{to_world}</transform>
        <film type="hdrfilm">
            <integer name="width" value="{w}"/><integer name="height" value="{h}"/>
            <rfilter type="{rfilter}"/>
        </film>
    </sensor>"""


def el(xml):
    import xml.etree.ElementTree as ET
    return ET.fromstring(xml)


# ---- transforms ----

def test_transform_ops_compose_in_order():
    m = mi.parse_transform(el("""<transform name="to_world">
        <scale value="2"/><rotate z="1" angle="90"/><translate x="1" y="2" z="3"/>
    </transform>"""))
    p = m @ [1.0, 0.0, 0.0, 1.0]
    # scale: (2,0,0); rotate 90 about z: (0,2,0); translate: (1,4,3)
    assert np.allclose(p[:3], [1.0, 4.0, 3.0])


def test_transform_matrix_row_major_with_commas_and_vector_forms():
    m = mi.parse_transform(el("""<transform name="t">
        <matrix value="1, 0, 0, 5,  0 1 0 6,  0 0 1 7,  0 0 0 1"/></transform>"""))
    assert np.allclose(m[:3, 3], [5, 6, 7])
    m = mi.parse_transform(el("""<transform name="t">
        <translate value="1 2 3"/><scale x="2"/><rotate value="1 0 0" angle="180"/>
    </transform>"""))
    assert np.allclose(m @ [0, 0, 0, 1.0], [2, -2, -3, 1])  # scale y, z default to 1


def test_lookat_matches_mitsuba_columns():
    m = mi.parse_transform(el("""<transform name="t">
        <lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>"""))
    # columns: left = up x dir, up, dir = normalize(target - origin), origin
    assert np.allclose(m[:3, 2], [0, 0, -1])
    assert np.allclose(m[:3, 1], [0, 1, 0])
    assert np.allclose(m[:3, 0], np.cross([0, 1, 0], [0, 0, -1]))
    assert np.allclose(m[:3, 3], [0, 0, 5])


# ---- camera ----

@pytest.mark.parametrize("axis,expect", [
    ("x", (1.0, 0.5)), ("y", (2.0, 1.0)), ("smaller", (2.0, 1.0)), ("larger", (1.0, 0.5)),
    ("diagonal", (2 / math.sqrt(5), 1 / math.sqrt(5))),
])
def test_fov_axes(tmp_path, axis, expect):
    path = write(tmp_path, sensor_xml('<lookat origin="0,0,0" target="0,0,1" up="0,1,0"/>',
                                      fov="90", extra=f'<string name="fov_axis" value="{axis}"/>'))
    s = mi.load_mitsuba(path)
    assert (s.film["width"], s.film["height"]) == (200, 100)
    assert np.allclose(s.camera["screen"], [-expect[0], expect[0], -expect[1], expect[1]])


def test_fov_from_focal_length_is_diagonal():
    tx, ty = mi.fov_tangents(60.0, "diagonal", 300, 400)
    assert math.isclose(math.hypot(tx, ty), math.tan(math.radians(30)))
    assert math.isclose(tx / ty, 0.75)


def project(scene, p_mitsuba):
    """Lantern screen position (x right, y up, on z=-1) of a Mitsuba world point."""
    p = mi.Y_UP_TO_Z_UP @ np.append(p_mitsuba, 1.0)
    local = np.linalg.inv(np.asarray(scene.camera["to_world"])) @ p
    assert local[2] < 0, "point is behind the Lantern camera"
    return local[0] / -local[2], local[1] / -local[2]


@pytest.mark.parametrize("to_world", [
    '<lookat origin="0,0,0" target="0,0,1" up="0,1,0"/>',
    '<rotate y="1" angle="30"/><translate x="2" y="-1" z="0.5"/>',
    '<matrix value="-1 0 0 0 0 1 0 1 0 0 -1 6.8 0 0 0 1"/>',   # the Bitterli Cornell box
])
def test_camera_handedness_no_mirror(tmp_path, to_world):
    """Mitsuba's camera-local +X is the image's left and +Y its top: a point there must land
    left / top in Lantern's window too (a left-right mirror is the easy mistake)."""
    path = write(tmp_path, sensor_xml(to_world))
    s = mi.load_mitsuba(path, width=64, height=32)
    m = mi.parse_transform(el(f'<transform name="t">{to_world}</transform>'))
    for local, check in (([0.3, 0.0, 2.0], lambda x, y: x < -0.1 and abs(y) < 1e-6),
                         ([-0.3, 0.0, 2.0], lambda x, y: x > 0.1 and abs(y) < 1e-6),
                         ([0.0, 0.3, 2.0], lambda x, y: y > 0.1 and abs(x) < 1e-6)):
        x, y = project(s, (m @ np.append(local, 1.0))[:3])
        assert check(x, y), (local, x, y)
    to_world_l = np.asarray(s.camera["to_world"])
    assert np.allclose(to_world_l[:3, :3].T @ to_world_l[:3, :3], np.eye(3), atol=1e-9)
    assert np.linalg.det(to_world_l[:3, :3]) > 0


def test_clip_and_resolution_override_keeps_aspect(tmp_path):
    path = write(tmp_path, sensor_xml('<lookat origin="0,0,0" target="0,0,1" up="0,1,0"/>',
                                      extra='<float name="near_clip" value="0.5"/>'
                                            '<float name="far_clip" value="50"/>'))
    s = mi.load_mitsuba(path, width=100)
    assert (s.film["width"], s.film["height"]) == (100, 50)
    assert s.camera["clip"] == [0.5, 50.0]
    assert s.metadata["rfilter"] == "tent"
    assert 1.4 < s.film["filter_width"] < 1.55   # tent r=1: same std as Blackman-Harris ~1.47


# ---- shapes, materials, parameters ----

def scene_xml_shapes(extra=""):
    return f"""
    <default name="depth" value="7"/>
    <default name="red" value="0.8"/>
    <integrator type="path"><integer name="max_depth" value="$depth"/></integrator>
    <bsdf type="twosided" id="red"><bsdf type="diffuse">
        <rgb name="reflectance" value="$red, 0.1, 0.1"/></bsdf></bsdf>
    <bsdf type="roughconductor" id="metal"><float name="alpha" value="0.1"/></bsdf>
    <bsdf type="plastic" id="plastic"><rgb name="diffuse_reflectance" value="0.2 0.3 0.4"/></bsdf>
    <shape type="rectangle" id="floor">
        <transform name="to_world"><scale x="2" y="3"/><rotate x="1" angle="-90"/>
            <translate y="-1"/></transform>
        <ref id="red"/>
    </shape>
    <shape type="cube" id="box"><ref id="metal"/></shape>
    <shape type="sphere" id="ball"><point name="center" x="0" y="5" z="0"/>
        <float name="radius" value="0.5"/><ref id="plastic"/></shape>
    <shape type="rectangle" id="lamp">
        <transform name="to_world"><rotate x="1" angle="90"/><translate y="4"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="10, 5, 1"/></emitter>
    </shape>
    {extra}"""


def mesh(scene, name):
    return next(m for m in scene.meshes if m["name"] == name)


def area(m):
    p = m["positions"].astype(np.float64)[m["indices"].astype(np.int64)]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()


def geometric_normals(m):
    p = m["positions"].astype(np.float64)[m["indices"].astype(np.int64)]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_shapes_materials_defaults(tmp_path):
    s = mi.load_mitsuba(write(tmp_path, scene_xml_shapes()), params={"red": "0.6"})
    assert s.metadata["max_depth"] == 7
    floor = mesh(s, "floor")
    assert math.isclose(area(floor), 4 * 2 * 3, rel_tol=1e-6)
    # a Mitsuba floor at y = -1 facing +Y is a Lantern floor at z = -1 facing +Z (Y up -> Z up)
    assert np.allclose(floor["positions"][:, 2], -1.0)
    assert np.allclose(geometric_normals(floor), [0, 0, 1], atol=1e-6)
    assert np.allclose(floor["normals"], [0, 0, 1], atol=1e-6)
    assert np.allclose(np.ptp(floor["positions"][:, :2], axis=0), [4, 6])
    assert s.materials[floor["material_ids"][0]]["base_color"] == [0.6, 0.1, 0.1]

    box = mesh(s, "box")
    assert len(box["indices"]) == 12 and math.isclose(area(box), 24.0, rel_tol=1e-6)
    centres = box["positions"][box["indices"].astype(np.int64)].mean(axis=1)
    assert (np.einsum("ij,ij->i", geometric_normals(box), centres) > 0).all()  # outward

    ball = mesh(s, "ball")
    r = np.linalg.norm(ball["positions"] - [0, 0, 5], axis=1)   # Mitsuba (0,5,0) -> (0,0,5)
    assert np.allclose(r, 0.5, atol=1e-6)
    assert math.isclose(area(ball), 4 * math.pi * 0.25, rel_tol=2e-3)
    assert np.allclose(s.materials[ball["material_ids"][0]]["base_color"], [0.2, 0.3, 0.4])

    lamp = mesh(s, "lamp")
    mat = s.materials[lamp["material_ids"][0]]
    assert mat["emission"] == [10.0, 5.0, 1.0] and mat["base_color"] == [0.0, 0.0, 0.0]
    # one-sided emission: a non-emissive back just behind it, facing the other way
    back = mesh(s, "lamp_back")
    assert max(s.materials[back["material_ids"][0]]["emission"]) == 0
    nf, nb = geometric_normals(lamp)[0], geometric_normals(back)[0]
    assert np.allclose(nb, -nf, atol=1e-6)
    gap = (lamp["positions"][0] - back["positions"][0]) @ nf
    assert 0 < gap < 1e-2
    assert "lamp_back" not in [m["name"] for m in
                               mi.load_mitsuba(write(tmp_path, scene_xml_shapes()),
                                               one_sided_emitters=False).meshes]

    metal = s.materials[box["material_ids"][0]]
    assert metal["type"] == "conductor" and math.isclose(metal["roughness"], math.sqrt(0.1))
    assert metal["eta"] == [0.0] * 3 and metal["k"] == [1.0] * 3   # Mitsuba's "none"
    warn = [w for w in s.metadata["warnings"] if "imported as diffuse" in w]
    assert len(warn) == 1 and "roughconductor" not in warn[0] and "plastic" in warn[0]
    # Mitsuba's default distribution, kept for conductors; no compensation, as Mitsuba
    assert metal["distribution"] == "beckmann" and metal["multiscatter"] is False
    assert not [w for w in s.metadata["warnings"] if "Beckmann" in w]


def test_undefined_parameter_and_bad_ref(tmp_path):
    with pytest.raises(ValueError, match="undefined parameter"):
        mi.load_mitsuba(write(tmp_path, '<integrator type="path">'
                              '<integer name="max_depth" value="$nope"/></integrator>'))
    with pytest.raises(ValueError, match="no object with that id"):
        mi.load_mitsuba(write(tmp_path, '<shape type="cube"><ref id="missing"/></shape>'))


QUAD_OBJ = """# quad
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1 -1/-1/-1
"""


def test_obj_reader(tmp_path):
    (tmp_path / "quad.obj").write_text(QUAD_OBJ)
    pos, idx, nrm, uv = mi.read_obj(tmp_path / "quad.obj")
    assert pos.shape == (4, 3) and idx.tolist() == [[0, 1, 2], [0, 2, 3]]
    assert np.allclose(nrm, [0, 0, 1]) and np.allclose(uv[2], [1, 1])
    s = mi.load_mitsuba(write(tmp_path, '<shape type="obj"><string name="filename" '
                              'value="quad.obj"/><transform name="to_world">'
                              '<scale value="2"/></transform></shape>'))
    assert math.isclose(area(s.meshes[0]), 4.0)
    assert np.allclose(s.meshes[0]["normals"], [0, -1, 0], atol=1e-6)


def ply_bytes(fmt):
    verts = [(0, 0, 0, 0, 0, 1), (1, 0, 0, 0, 0, 1), (1, 1, 0, 0, 0, 1), (0, 1, 0, 0, 0, 1)]
    header = (f"ply\nformat {fmt} 1.0\ncomment test\nelement vertex 4\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              "element face 2\nproperty list uchar int vertex_indices\nend_header\n")
    faces = [(0, 1, 2), (0, 2, 3)]
    if fmt == "ascii":
        body = "".join(" ".join(map(str, v)) + "\n" for v in verts)
        body += "".join("3 " + " ".join(map(str, f)) + "\n" for f in faces)
        return (header + body).encode()
    bo = "<" if fmt == "binary_little_endian" else ">"
    body = b"".join(struct.pack(bo + "6f", *v) for v in verts)
    body += b"".join(struct.pack(bo + "B3i", 3, *f) for f in faces)
    return header.encode() + body


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian", "binary_big_endian"])
def test_ply_reader(tmp_path, fmt):
    (tmp_path / "quad.ply").write_bytes(ply_bytes(fmt))
    pos, idx, nrm, uv = mi.read_ply(tmp_path / "quad.ply")
    assert np.allclose(pos[2], [1, 1, 0]) and idx.tolist() == [[0, 1, 2], [0, 2, 3]]
    assert np.allclose(nrm, [0, 0, 1]) and uv is None


def test_ply_polygon_faces(tmp_path):
    data = (b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            b"property float z\nelement face 1\nproperty list uchar uint vertex_indices\n"
            b"end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    (tmp_path / "q.ply").write_bytes(data)
    _, idx, nrm, _ = mi.read_ply(tmp_path / "q.ply")
    assert idx.tolist() == [[0, 1, 2], [0, 2, 3]] and nrm is None


def test_cli_import(tmp_path):
    src = write(tmp_path, scene_xml_shapes(sensor_xml(
        '<lookat origin="0,1,-5" target="0,1,0" up="0,1,0"/>', w=40, h=30)))
    out = tmp_path / "s.lantern"
    r = subprocess.run([sys.executable, "-m", "lantern", "import-mitsuba", str(src), "-o",
                        str(out), "-D", "depth=3"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "--max-depth 3" in r.stderr and "plastic" in r.stderr
    s = lantern.load_scene(out)
    assert (s.film["width"], s.film["height"]) == (40, 30)
    assert len(s.meshes) == 5


# ---- BSDFs ----

def materials_of(tmp_path, bsdfs):
    """Import one cube per BSDF snippet; returns their materials in order (and the scene)."""
    shapes = "".join(f'<shape type="cube" id="s{i}">{b}</shape>' for i, b in enumerate(bsdfs))
    s = mi.load_mitsuba(write(tmp_path, shapes))
    return [s.materials[mesh(s, f"s{i}")["material_ids"][0]] for i in range(len(bsdfs))], s


CU_ETA, CU_K = "0.200438, 0.924033, 1.10221", "3.91295, 2.45285, 2.14219"   # veach-mis


def test_conductor_mapping(tmp_path):
    (veach, preset, smooth, aniso, tinted_tex), s = materials_of(tmp_path, [
        f"""<bsdf type="twosided" id="plate"><bsdf type="roughconductor">
            <float name="alpha" value="0.05"/><string name="distribution" value="beckmann"/>
            <rgb name="specular_reflectance" value="0.3, 0.3, 0.3"/>
            <rgb name="eta" value="{CU_ETA}"/><rgb name="k" value="{CU_K}"/></bsdf></bsdf>""",
        """<bsdf type="roughconductor" id="alu"><string name="material" value="Al"/>
            <string name="distribution" value="ggx"/><float name="alpha" value="0.25"/></bsdf>""",
        """<bsdf type="conductor"><string name="material" value="Au"/>
            <spectrum name="eta" value="1.5"/></bsdf>""",
        """<bsdf type="roughconductor" id="brushed"><float name="alpha_u" value="0.04"/>
            <float name="alpha_v" value="0.16"/><string name="distribution" value="ggx"/>
            </bsdf>""",
        """<bsdf type="conductor"><string name="material" value="a-C"/>
            <rgb name="specular_reflectance" value="2, 0.5, -1"/></bsdf>""",
    ])
    assert veach["type"] == "conductor"
    assert math.isclose(veach["roughness"], math.sqrt(0.05))        # alpha = roughness^2
    assert np.allclose(veach["eta"], [0.200438, 0.924033, 1.10221])
    assert np.allclose(veach["k"], [3.91295, 2.45285, 2.14219])
    assert veach["base_color"] == [0.3] * 3                          # specular_reflectance
    assert np.allclose(preset["eta"], [1.6574599595, 0.8803689579, 0.5212287346])
    assert np.allclose(preset["k"], [9.2238691996, 6.2695232477, 4.8370012281])
    assert preset["roughness"] == 0.5 and preset["base_color"] == [1.0] * 3
    # a smooth conductor; an explicit eta wins over the preset (k then defaults to 1, as Mitsuba)
    assert smooth["roughness"] == 0.0 and smooth["eta"] == [1.5] * 3 and smooth["k"] == [1.0] * 3
    assert math.isclose(aniso["roughness"], math.sqrt(math.sqrt(0.04 * 0.16)))
    assert tinted_tex["base_color"] == [1.0, 0.5, 0.0]              # clamped, with a warning
    w = s.metadata["warnings"]
    assert not [x for x in w if "Beckmann" in x]                    # conductors keep it
    assert veach["distribution"] == "beckmann" and veach["multiscatter"] is False
    assert any("anisotropic" in x for x in w) and any("clamped" in x for x in w)
    assert not any("imported as diffuse" in x for x in w)

    (unknown,), s = materials_of(tmp_path, ['<bsdf type="conductor">'
                                            '<string name="material" value="Xx"/></bsdf>'])
    assert unknown["eta"] == [0.0] * 3 and any("'Xx'" in x for x in s.metadata["warnings"])


def test_dielectric_mapping(tmp_path):
    (glass, water, rough, numbers), s = materials_of(tmp_path, [
        '<bsdf type="dielectric"/>',    # Mitsuba's defaults: bk7 in air
        """<bsdf type="twosided"><bsdf type="dielectric"><string name="int_ior" value="water"/>
            <string name="ext_ior" value="air"/>
            <rgb name="specular_transmittance" value="0.9, 0.8, 0.7"/></bsdf></bsdf>""",
        """<bsdf type="roughdielectric"><float name="alpha" value="0.09"/>
            <string name="distribution" value="ggx"/><string name="int_ior" value="BK7"/>
            <string name="ext_ior" value="water"/></bsdf>""",
        """<bsdf type="dielectric"><float name="int_ior" value="1.0"/>
            <float name="ext_ior" value="1.33"/></bsdf>""",
    ])
    assert glass["type"] == "dielectric" and glass["roughness"] == 0.0
    assert math.isclose(glass["ior"], 1.5046 / 1.000277, rel_tol=1e-6)
    assert glass["base_color"] == [1.0] * 3
    assert math.isclose(water["ior"], 1.3330 / 1.000277, rel_tol=1e-6)
    assert water["base_color"] == [0.9, 0.8, 0.7]                   # transmission tint
    assert math.isclose(rough["roughness"], 0.3) and math.isclose(rough["ior"], 1.5046 / 1.333)
    assert math.isclose(numbers["ior"], 1.0 / 1.33)                 # an air bubble in water
    assert not any("Beckmann" in x or "diffuse" in x for x in s.metadata["warnings"])
    with pytest.raises(ValueError, match="unknown index of refraction"):
        materials_of(tmp_path, ['<bsdf type="dielectric"><string name="int_ior" '
                                'value="unobtainium"/></bsdf>'])


def test_plastic_and_principled_stay_diffuse(tmp_path):
    (plastic, principled), s = materials_of(tmp_path, [
        """<bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/>
            </bsdf>""",
        '<bsdf type="principled"><rgb name="base_color" value="0.4, 0.5, 0.6"/></bsdf>',
    ])
    assert plastic == {**plastic, "type": "diffuse", "base_color": [0.1, 0.2, 0.3]}
    assert principled["type"] == "diffuse" and principled["base_color"] == [0.4, 0.5, 0.6]
    warn = [x for x in s.metadata["warnings"] if "imported as diffuse" in x]
    assert len(warn) == 1 and "roughplastic (1)" in warn[0] and "principled (1)" in warn[0]


def test_add_material_eta_k_validation():
    s = lantern.Scene()
    m = s.materials[s.add_material("cu", type="conductor", eta=(0.2, 0.9, 1.1), k=3.9)]
    assert m["eta"] == [0.2, 0.9, 1.1] and m["k"] == [3.9] * 3
    assert "eta" not in s.materials[s.add_material("f82", type="conductor")]
    with pytest.raises(ValueError, match="conductors only"):
        s.add_material("glass", type="dielectric", eta=1.5, k=0.0)
    with pytest.raises(ValueError, match="both eta and k"):
        s.add_material("half", type="conductor", eta=1.5)
    with pytest.raises(ValueError, match=">= 0"):
        s.add_material("neg", type="conductor", eta=(0.2, -1.0, 1.0), k=1.0)


def fresnel_conductor(cos_i, eta, k):
    """Unpolarised reflectance of eta + i k (numpy complex), the textbook formula."""
    n = np.asarray(eta) + 1j * np.asarray(k)
    sin2 = 1.0 - cos_i ** 2
    cos_t = np.sqrt(1.0 - sin2 / n ** 2)
    r_s = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    r_p = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return 0.5 * (np.abs(r_s) ** 2 + np.abs(r_p) ** 2)


def test_complex_fresnel_mirror_renders_fresnel_times_reflectance():
    """A smooth conductor facing the camera under a white sky: each pixel is
    specular_reflectance x F(eta, k) at normal incidence (the binding reads eta, k and the
    scale); the same base colour as an F82 conductor would be F0 itself."""
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    eta, k = [0.200438, 0.924033, 1.10221], [3.91295, 2.45285, 2.14219]
    images = []
    for kwargs in ({"eta": eta, "k": k, "base_color": [0.5, 0.8, 1.0]},
                   {"base_color": [0.5, 0.8, 1.0]}):
        s = lantern.Scene()
        s.film.update(width=4, height=4)
        s.camera["screen"] = [-0.01, 0.01, -0.01, 0.01]
        s.world["color"] = [1.0, 1.0, 1.0]
        mid = s.add_material("metal", type="conductor", roughness=0.0, **kwargs)
        s.add_mesh([[-5, -5, -1], [5, -5, -1], [5, 5, -1], [-5, 5, -1]], [[0, 1, 2], [0, 2, 3]],
                   material=mid)
        images.append(np.asarray(lantern.render(s, spp=4, max_depth=4, integrator="pt"),
                                 dtype=np.float64))
    expect = np.array([0.5, 0.8, 1.0]) * fresnel_conductor(1.0, eta, k)
    assert np.allclose(images[0].mean(axis=(0, 1)), expect, rtol=2e-3), (images[0][0, 0], expect)
    assert np.allclose(images[1].mean(axis=(0, 1)), [0.5, 0.8, 1.0], rtol=2e-3)


# ---- the Bitterli Cornell box against Tungsten ----

def downsample(img, f):
    """f x f box means of an (H, W, C) image (H, W multiples of f), RGB."""
    h, w = img.shape[0] // f, img.shape[1] // f
    return img[..., :3].reshape(h, f, w, f, 3).mean(axis=(1, 3))


def reference_block_se(ref, f, block=8):
    """Per block of the f x downsampled image, the standard error of Tungsten's own block mean
    (one stored render: no seeds), from its pixels' noise: the second difference along rows,
    x_i - (x_i-1 + x_i+1) / 2, has variance sigma^2 (1.5 - 2 rho) = sigma^2 for the tent's
    neighbour correlation rho = 1/4 (radius one pixel), and the block mean of N pixels
    sigma^2 (1 + 2 rho)^2 / N; sigma^2 from the median of the squares (/ 0.455, a normal's),
    so that edges and shading in the block do not count as noise."""
    d = ref[:, 1:-1] - 0.5 * (ref[:, :-2] + ref[:, 2:])
    d = np.concatenate([d[:, :1], d, d[:, -1:]], axis=1)
    n = f * block
    bh, bw = ref.shape[0] // n, ref.shape[1] // n
    sq = (d[:bh * n, :bw * n] ** 2).reshape(bh, n, bw, n, 3).transpose(0, 2, 1, 3, 4)
    sigma2 = np.median(sq.reshape(bh, bw, n * n, 3), axis=2) / 0.455
    return np.sqrt(2.25 * sigma2 / (n * n))


def cornell_comparison(seeds=None, spp=None, size=128, seed0=7):
    """Render the imported Cornell box at the reference's 1024^2 with its pixel filter (the
    importer's Blackman-Harris of the tent's standard deviation), `seeds` seeds of `spp`, and
    box-downsample both to size x size as the reference was made: Lantern's pixels and
    Tungsten's then average the same footprint. Emitter pixels (and a 1-pixel rim) masked;
    the blocks compared are the 8x8 blocks clear of that mask."""
    spp, seeds = spp or CORNELL_SPP, seeds or CORNELL_SEEDS
    ref = imageio.read_image(SCENES / "cornell-box" / "TungstenRender.exr").astype(np.float64)
    f = ref.shape[0] // size
    scene = mi.load_mitsuba(SCENES / "cornell-box" / "scene.xml", ref.shape[1], ref.shape[0])
    start = time.monotonic()
    imgs = [downsample(np.asarray(lantern.render(scene, spp=spp, seed=seed0 + k,
                                                 max_depth=scene.metadata["max_depth"],
                                                 integrator="pt"),
                                  dtype=np.float64), f) for k in range(seeds)]
    seconds = time.monotonic() - start
    hot = (ref.max(axis=2) > 1.5).reshape(size, f, size, f).any(axis=(1, 3))
    rim = hot.copy()
    rim[1:] |= hot[:-1]
    rim[:-1] |= hot[1:]
    rim[:, 1:] |= rim[:, :-1].copy()
    rim[:, :-1] |= rim[:, 1:].copy()
    keep = ~rim
    ref_se = reference_block_se(ref, f)
    ref = downsample(ref, f)
    img = np.mean(imgs, axis=0)
    blocks = metrics.block_means(keep.astype(np.float64), 8) == 1.0
    return {
        "seconds": seconds, "imgs": imgs, "ref": ref, "blocks": blocks,
        "ref_block_rel_se": (ref_se / metrics.block_means(ref, 8))[blocks],
        "rrmse": metrics.relative_rmse(img, ref, mask=keep),
        "rrmse_8x": metrics.relative_rmse(metrics.block_means(img, 8),
                                          metrics.block_means(ref, 8), mask=blocks),
        "left_right": (img[40:90, 4:12].mean(axis=(0, 1)), img[40:90, -12:-4].mean(axis=(0, 1))),
        "warnings": scene.metadata["warnings"],
    }


# 16 seeds of 1 spp at Tungsten's 1024^2 (the samples of 8 x 128 at 128^2, as before; 16 seeds
# for the Bonferroni threshold), both box-downsampled 8x. Rendered at 128^2 with the tent
# scaled to that film, the blocks differed from the reference by 2.1 % rms and up to 30 % where
# walls meet (the footprints differed, not the light); at the reference's own resolution and
# filter they differ by their noise (0.67 % rms, worst |z| 3.5 against 7.7 over 756 values).
# Tungsten's reference is one stored image: its own block noise (reference_block_se) is 0.02 %
# (median; at most 0.14 %) against Lantern's 0.30 %, and the 0.3 % cap covers it (asserted).
# The cap also states the renderers' systematic difference in the image mean: +0.06..+0.16 %
# measured (16 x 1: +0.16 %; 8 x 128 at 128^2: +0.09 %; four seeds of 256 spp +0.06..+0.12 %).
CORNELL_SEEDS, CORNELL_SPP, CORNELL_CAP = 14, 1, 0.003


@pytest.mark.skipif(not (SCENES / "cornell-box" / "TungstenRender.exr").exists(),
                    reason="shared scenes not present")
def test_cornell_box_matches_tungsten():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    r = cornell_comparison()
    print(f"\ncornell-box 1024^2 {CORNELL_SEEDS} x {CORNELL_SPP} spp ({r['seconds']:.1f} s), "
          f"box-downsampled 8x: relative RMSE {r['rrmse']:.2%} per 128^2 pixel (Mitsuba 2.9%), "
          f"{r['rrmse_8x']:.2%} per 8x8 block; Tungsten's block noise "
          f"{np.median(r['ref_block_rel_se']):.3%} (median), {r['ref_block_rel_se'].max():.3%} "
          f"(max)")
    left, right = r["left_right"]
    assert left[0] > 2 * left[1] and right[1] > 2 * right[0]   # red wall left, green right
    assert r["ref_block_rel_se"].max() < 0.5 * CORNELL_CAP     # the cap covers the reference
    # per block, the image mean and the block-weighted mean against the reference (exact but
    # for the cap), with the 1 % / +5 % block / swapped-channel controls (tests/README.md)
    metrics.assert_agreement("cornell-box vs Tungsten", r["imgs"], r["ref"], block=8,
                             mask=r["blocks"], bias_cap=CORNELL_CAP)
    assert r["rrmse"] < 0.05 and r["rrmse_8x"] < 0.02


# ---- Bitterli's veach-mis against Tungsten ----

def sphere_emitter_blocks(scene, width, height, factor):
    """(hit, grown): (height // factor, width // factor) blocks of a width x height image whose
    camera rays hit an emissive sphere (centre and radius from its tessellation), and those
    grown by one block: the emitters seen directly. Pixel rows run top to bottom."""
    cam = scene.camera
    xmin, xmax, ymin, ymax = cam["screen"]
    to_world = np.asarray(cam["to_world"], dtype=np.float64)
    x = xmin + (np.arange(width) + 0.5) / width * (xmax - xmin)
    y = ymax - (np.arange(height) + 0.5) / height * (ymax - ymin)
    d = np.stack(np.broadcast_arrays(x[None, :], y[:, None], -1.0), axis=-1) @ to_world[:3, :3].T
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    hit = np.zeros((height, width), dtype=bool)
    for m in scene.meshes:
        if max(scene.materials[int(m["material_ids"][0])]["emission"]) <= 0:
            continue
        p = m["positions"].astype(np.float64)
        oc = p.mean(axis=0) - to_world[:3, 3]
        r = np.linalg.norm(p - p.mean(axis=0), axis=1).max()
        t = d @ oc
        hit |= (t > 0) & (oc @ oc - t * t <= r * r)
    blocks = hit.reshape(height // factor, factor, width // factor, factor).any(axis=(1, 3))
    grown = blocks.copy()
    grown[1:] |= blocks[:-1]
    grown[:-1] |= blocks[1:]
    grown[:, 1:] |= grown[:, :-1].copy()
    grown[:, :-1] |= grown[:, 1:].copy()
    return blocks, grown


def veach_sixths(img, ref, mask):
    """img / ref - 1 over the masked pixels of each horizontal sixth, top to bottom."""
    out = []
    for rows in np.array_split(np.arange(img.shape[0]), 6):
        m = np.zeros_like(mask)
        m[rows] = mask[rows]
        out.append(img[m].mean() / ref[m].mean() - 1.0)
    return np.array(out)


def veach_comparison(seeds=None, indirect_seeds=None, factor=8, max_depth=2, seed0=7):
    """Render the imported veach-mis at its 1280x720 with its filter, `seeds` seeds of 1 spp,
    and box-downsample by factor as Tungsten's reference is (both then average the same
    footprint); the three sphere lights seen directly (and a 1-pixel rim) masked, the 8x8
    blocks clear of them compared.

    Tungsten's reference holds direct light only: Mitsuba 3 renders it at max_depth 2 (not
    the file's 3) to 0.06% (docs/mitsuba_import.md). So Lantern is compared with it at
    max_depth 2, and the one indirect bounce of the file's max_depth 3 separately: the first
    `indirect_seeds` seeds rendered again at that depth, their gain over max_depth 2 outside
    the highlights (paired, seed by seed) compared with Mitsuba's."""
    seeds = seeds or VEACH_SEEDS
    indirect_seeds = VEACH_INDIRECT_SEEDS if indirect_seeds is None else indirect_seeds
    folder = SCENES / "veach-mis"
    ref = imageio.read_image(folder / "TungstenRender.exr").astype(np.float64)
    h, w = ref.shape[0] // factor, ref.shape[1] // factor
    scene = mi.load_mitsuba(folder / "scene.xml", ref.shape[1], ref.shape[0])

    def renders(depth, n):
        return [downsample(np.asarray(lantern.render(scene, spp=1, max_depth=depth,
                                                     seed=seed0 + k, integrator="pt"),
                                                     dtype=np.float64), factor)
                for k in range(n)]
    start = time.monotonic()
    imgs = renders(max_depth, seeds)
    seconds = time.monotonic() - start
    imgs3 = renders(scene.metadata["max_depth"], indirect_seeds)
    lights, masked = sphere_emitter_blocks(scene, ref.shape[1], ref.shape[0], factor)
    keep = ~masked
    hot_ref = ref.reshape(h, factor, w, factor, 3).max(axis=(1, 3, 4))
    ref = downsample(ref, factor)
    img = np.mean(imgs, axis=0)
    glossy = keep & (ref.max(axis=2) > 1.0)          # the plates' highlights
    rest = keep & ~glossy
    rows = h // 8 * 8                                  # whole 8x8 blocks (90 rows: 88)
    blocks = metrics.block_means(keep[:rows].astype(np.float64), 8) == 1.0
    gain = np.array([b[rest].mean() / a[rest].mean() - 1.0 for a, b in zip(imgs, imgs3)])
    if not indirect_seeds:  # the Tungsten comparison alone (tools/false_alarm.py)
        return {"imgs": [im[:rows] for im in imgs], "ref": ref[:rows], "blocks": blocks}
    return {
        "seconds": seconds, "size": (w, h), "seeds": seeds, "max_depth": max_depth,
        "file_max_depth": scene.metadata["max_depth"], "indirect_seeds": indirect_seeds,
        "imgs": [im[:rows] for im in imgs], "ref": ref[:rows], "blocks": blocks,
        "glossy_blocks": blocks & (metrics.block_means(glossy[:rows].astype(np.float64), 8) > 0),
        "mean_rel": img[keep].mean() / ref[keep].mean() - 1.0,
        "glossy_rel": img[glossy].mean() / ref[glossy].mean() - 1.0,
        "diffuse_rel": img[rest].mean() / ref[rest].mean() - 1.0,
        "sixths_rel": veach_sixths(img, ref, keep),
        "glossy_share": ref[glossy].sum() / ref[keep].sum(),
        "rrmse": metrics.relative_rmse(img, ref, mask=keep),
        "indirect_gains": gain, "indirect_gain": gain.mean(),
        "indirect_gain_se": gain.std(ddof=1) / math.sqrt(len(gain)),
        "indirect_gain_sixths": veach_sixths(np.mean(imgs3, axis=0),
                                             np.mean(imgs[:indirect_seeds], axis=0), rest),
        "file_depth_rel": np.mean(imgs3, axis=0)[keep].mean() / ref[keep].mean() - 1.0,
        "light_ref_min": hot_ref[lights].min() if lights.any() else 0.0,
        "masked_fraction": masked.mean(),
        "warnings": scene.metadata["warnings"],
    }


_VEACH = {}


def veach_result():
    """veach_comparison() once per test session (three tests read it)."""
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    if "r" not in _VEACH:
        _VEACH["r"] = veach_comparison()
        r = _VEACH["r"]
        w, h = r["size"]
        print(f"\nveach-mis 1280x720 {r['seeds']} x 1 spp pt max_depth {r['max_depth']} "
              f"({r['seconds']:.1f} s), box-downsampled to {w}x{h}: mean {r['mean_rel']:+.3%} "
              f"(Mitsuba +0.06%), by sixths {np.round(r['sixths_rel'] * 100, 2).tolist()} %, "
              f"plates' highlights {r['glossy_rel']:+.2%} ({r['glossy_share']:.0%} of the "
              f"light), the rest {r['diffuse_rel']:+.2%}; relative RMSE {r['rrmse']:.2%} per "
              f"pixel; {r['masked_fraction']:.1%} of the pixels masked\n"
              f"max_depth {r['file_max_depth']} ({r['indirect_seeds']} seeds, paired): the rest "
              f"{r['indirect_gain']:+.2%} +- {r['indirect_gain_se']:.2%} over max_depth "
              f"{r['max_depth']} (Mitsuba +9.03%), by sixths "
              f"{np.round(r['indirect_gain_sixths'] * 100, 2).tolist()} % (Mitsuba "
              f"{VEACH_MITSUBA_INDIRECT_SIXTHS}); whole image {r['file_depth_rel']:+.2%} "
              f"against Tungsten (Mitsuba +4.4%)")
    return _VEACH["r"]


VEACH_REF = (SCENES / "veach-mis" / "TungstenRender.exr").exists()
# Mitsuba 3.9.1 scalar_rgb `path` at 160x90, 4096 spp: max_depth 3 over max_depth 2 outside
# the plates' highlights by horizontal sixths top to bottom, % (docs/mitsuba_import.md; the
# whole rest +8.90 % there)
VEACH_MITSUBA_INDIRECT_SIXTHS = [2.44, 2.93, 5.16, 19.85, 19.78, 17.99]
# 16 seeds of 1 spp at 1280x720 (a sixteenth of the old one 1024-spp render at 160x90 a seed:
# the same samples), 4 of them again at max_depth 3 (the old 256 spp at 160x90)
VEACH_SEEDS, VEACH_INDIRECT_SEEDS = 16, 4


# long (2026-12-05): 193 s of one thread, CI's largest single Python test; bench/long_tests.sh
@pytest.mark.long
@pytest.mark.skipif(not VEACH_REF, reason="no veach-mis reference in ../shared/scenes")
def test_veach_mis_plates_match_tungsten():
    """The four rough plates' highlights (reference pixels above 1): Beckmann conductors of
    alpha 0.01 to 0.25 with complex Fresnel, as Tungsten renders them: their blocks are held,
    one by one, to their noise in test_veach_mis_matches_tungsten's comparison."""
    r = veach_result()
    assert not any("imported as diffuse" in x for x in r["warnings"])
    assert not any("Beckmann" in x for x in r["warnings"])  # conductors keep Beckmann now
    assert r["light_ref_min"] > 2.0       # the mask lies on the lights (orientation, geometry)
    assert r["glossy_blocks"].sum() >= 20  # the highlights are among the blocks compared
    res = metrics.compare_renders(r["imgs"], r["ref"], block=8, mask=r["glossy_blocks"],
                                  bias_cap=VEACH_CAP)
    print(f"highlight blocks only: {res}")
    # per block only: their mean resolves ~1.2 %, the whole image's (the next test) 0.5 %
    assert res.blocks_passed, str(res)
    ctls = [(label, c) for label, c in metrics.negative_controls(
        r["imgs"], r["ref"], block=8, mask=r["glossy_blocks"], bias_cap=VEACH_CAP)
        if "block" in label]
    assert len(ctls) == 2 and not any(c.blocks_passed for _, c in ctls), ctls  # +-5 %


# The cap: Mitsuba against Tungsten +0.06 %; Lantern's block-weighted mean reads +0.11 % (8 x 1)
VEACH_CAP = 0.002


@pytest.mark.skipif(not VEACH_REF, reason="no veach-mis reference in ../shared/scenes")
def test_veach_mis_matches_tungsten():
    """Tungsten's reference is direct light only (Mitsuba at max_depth 2 matches it to 0.06%);
    at that depth every block, the image mean and the block-weighted mean agree (the floor's
    +14..18% of the one indirect bounce would show in its blocks), with the 1 % / +5 % block /
    channel-swap controls (tests/README.md). The image mean is the highlights' (fireflies of
    the small lights in the rough plates); the block-weighted mean is what sees 1 %. Tungsten's
    own block noise (reference_block_se) is 0.005 % (median; at most 0.05 %): exact here."""
    r = veach_result()
    assert r["max_depth"] == 2 and r["file_max_depth"] == 3
    metrics.assert_agreement("veach-mis max_depth 2 vs Tungsten", r["imgs"], r["ref"], block=8,
                             mask=r["blocks"], bias_cap=VEACH_CAP)


@pytest.mark.skipif(not VEACH_REF, reason="no veach-mis reference in ../shared/scenes")
def test_veach_mis_indirect_bounce_matches_mitsuba():
    """The file's max_depth 3 adds one indirect bounce that Tungsten's reference lacks; what it
    adds outside the highlights (light the plates and walls send onto the floor) matches
    Mitsuba 3's max_depth 3 over max_depth 2, at the same footprint (1280x720 box-downsampled):
    paired seeds, |gain - Mitsuba's| <= cap + t se, and a +-1 % bias of the max_depth 3
    renders (+-1.09 points of gain) must fail. Mitsuba's numbers are stored figures, not
    images: no block test, and the sixths against its 160x90 figures keep a stated 3 points."""
    r = veach_result()
    gains = r["indirect_gains"]
    t = metrics.z_threshold(1, 1e-3, len(gains) - 1)

    def within(g):
        se = g.std(ddof=1) / math.sqrt(len(g))
        return abs(g.mean() * 100 - VEACH_MITSUBA_INDIRECT_1280) <= VEACH_GAIN_CAP + t * se * 100
    print(f"indirect gain {gains.mean():+.3%} +- {r['indirect_gain_se']:.3%} against Mitsuba's "
          f"{VEACH_MITSUBA_INDIRECT_1280}% (allowed {VEACH_GAIN_CAP:.2f} + {t:.1f} se points)")
    assert within(gains)
    for bias in (0.01, -0.01):  # negative controls
        assert not within((1.0 + gains) * (1.0 + bias) - 1.0), bias
    # (at 160x90, one render of 1024 spp: +8.8 %, Mitsuba's 160x90 figure +8.90 %)
    assert np.allclose(r["indirect_gain_sixths"] * 100, VEACH_MITSUBA_INDIRECT_SIXTHS, atol=3.0)


# Mitsuba at 1280x720, 128 spp, box-downsampled 8x, masked as the test masks, against Tungsten
# (docs/mitsuba_import.md): outside the highlights +9.10 % at max_depth 3, +0.06 % at 2, so
# the bounce adds 1.0910 / 1.0006 - 1 = 9.03 %. The cap (points) covers the table's rounding and
# Mitsuba's own noise (~0.03 points, judged from Lantern's per-sample noise at its 128 spp);
# measured +9.00 +- 0.05 % (4 seeds of 1 spp at 1280x720, paired)
VEACH_MITSUBA_INDIRECT_1280, VEACH_GAIN_CAP = 9.03, 0.2
