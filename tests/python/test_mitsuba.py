"""Mitsuba 3 XML importer (python/lantern/mitsuba/): parser and BSDF-mapping units on small
inline scenes. Bitterli's cornell-box and veach-mis rendered by Lantern against Tungsten's
references: test_mitsuba_tungsten.py."""
import math
import struct
import subprocess
import sys

import numpy as np
import pytest

import lantern
from lantern import mitsuba as mi


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
