"""Scene container: defaults, validation messages, native hand-off, the .lantern file."""
import io
import json
import zipfile

import numpy as np
import pytest

import lantern
from lantern import scenes
from lantern.scene import FORMAT_VERSION, Scene, load_scene


def one_triangle_scene():
    scene = Scene()
    scene.add_material("white")
    scene.add_mesh([[0, 0, -1], [1, 0, -1], [0, 1, -1]], [[0, 1, 2]], name="tri")
    return scene


def test_version_and_exports():
    assert lantern.__version__ == "0.1.0"
    for name in ("Scene", "load_scene", "Session", "render"):
        assert hasattr(lantern, name)


def test_empty_scene_defaults():
    scene = Scene().validate()
    assert (scene.film["width"], scene.film["height"]) == (64, 64)
    assert scene.world["color"] == [0.0, 0.0, 0.0]
    assert scene.camera["type"] == "perspective"
    # looking down -Z from the origin: identity camera-to-world
    assert np.array_equal(np.asarray(scene.camera["to_world"]), np.eye(4))
    assert scene.materials == [] and scene.meshes == [] and scene.lights == []


def test_to_native_types():
    scene = scenes.cornell_box(width=16, height=8)
    native = scene.to_native()
    assert set(native) == {"film", "camera", "world", "materials", "textures", "meshes",
                           "lights"}
    m = native["camera"]["to_world"]
    assert isinstance(m, np.ndarray) and m.dtype == np.float32 and m.shape == (4, 4)
    assert native["lights"][0]["to_world"].dtype == np.float32
    for mesh in native["meshes"]:
        assert mesh["positions"].dtype == np.float32 and mesh["positions"].flags.c_contiguous
        assert mesh["indices"].dtype == np.uint32 and mesh["indices"].shape[1] == 3
        assert mesh["material_ids"].dtype == np.uint32
        assert mesh["normals"] is None and mesh["uvs"] is None


def test_add_mesh_coerces_dtypes():
    scene = Scene()
    scene.add_material()
    pos = np.asfortranarray(np.random.default_rng(0).random((4, 3)))  # float64, F-order
    idx = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    uvs = np.zeros((4, 2), dtype=np.float64)
    scene.add_mesh(pos, idx, uvs=uvs, normals=pos.tolist())
    mesh = scene.validate().meshes[0]
    assert mesh["positions"].dtype == np.float32 and mesh["positions"].flags.c_contiguous
    assert mesh["indices"].dtype == np.uint32
    assert mesh["uvs"].dtype == np.float32 and mesh["normals"].dtype == np.float32
    assert mesh["material_ids"].dtype == np.uint32 and mesh["material_ids"].shape == (2,)


def test_nan_vertices_pass_through():
    scene = one_triangle_scene()
    scene.meshes[0]["positions"][0, 0] = np.nan
    scene.validate()  # the core drops degenerate/NaN triangles
    assert np.isnan(scene.to_native()["meshes"][0]["positions"][0, 0])


def test_material_by_name():
    scene = Scene()
    scene.add_material("a")
    red = scene.add_material("red", base_color=(1, 0, 0))
    scene.add_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], material="red")
    assert scene.meshes[0]["material_ids"].tolist() == [red]
    with pytest.raises(ValueError, match="no material named 'blue'"):
        scene.add_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], material="blue")


@pytest.mark.parametrize("mutate, message", [
    (lambda m: m.update(indices=np.array([[0, 1, 3]])), r"mesh 0 \('tri'\).*vertex index 3"),
    (lambda m: m.update(indices=np.array([[0, 1, -1]])), r"mesh 0 \('tri'\).*negative"),
    (lambda m: m.update(indices=np.array([0, 1, 2])), r"indices.*shape \(T, 3\)"),
    (lambda m: m.update(indices=np.array([[0.0, 1.0, 2.0]])), r"indices.*integer"),
    (lambda m: m.update(positions=np.zeros((3, 2))), r"positions.*\(N, 3\)"),
    (lambda m: m.update(normals=np.zeros((2, 3))), r"normals: 2 rows for 3 vertices"),
    (lambda m: m.update(uvs=np.zeros((3, 3))), r"uvs.*\(N, 2\)"),
    (lambda m: m.update(material_ids=np.array([1])), r"mesh 0 \('tri'\).*material id 1"),
    (lambda m: m.update(material_ids=np.array([0, 0])), r"2 entries for 1 triangles"),
    (lambda m: m.pop("positions"), r"missing positions"),
    (lambda m: m.update(visible_camera="yes"), r"visible_camera"),
])
def test_mesh_validation_messages(mutate, message):
    scene = one_triangle_scene()
    mutate(scene.meshes[0])
    with pytest.raises(ValueError, match=message):
        scene.validate()


@pytest.mark.parametrize("mutate, message", [
    (lambda s: s.film.update(width=0), r"film width.*>= 1"),
    (lambda s: s.film.update(height=2.5), r"film height.*integer"),
    (lambda s: s.camera.update(type="fisheye"), r"camera type"),
    (lambda s: s.camera.update(to_world=np.diag([2.0, 2.0, 2.0, 1.0])), r"rigid"),
    (lambda s: s.camera.update(to_world=np.eye(3)), r"4x4"),
    (lambda s: s.camera.update(screen=[1, -1, -1, 1]), r"xmin < xmax"),
    (lambda s: s.camera.update(clip=[1.0, 0.5]), r"clip"),
    (lambda s: s.world.update(color=[0, 0]), r"world color"),
    (lambda s: s.world.update(color=[0, np.nan, 0]), r"world color.*finite"),
    (lambda s: s.materials[0].update(type="glass"), r"material 0 \('white'\).*unknown type"),
    # above 1 where the base colour is also a Fresnel F0 (a diffuse albedo may be: Cycles')
    (lambda s: s.materials[0].update(type="conductor", base_color=[2, 0, 0]),
     r"base_color.*\[0, 1\].*conductor"),
    (lambda s: s.materials[0].update(emission=[-1, 0, 0]), r"emission.*>= 0"),
    (lambda s: s.lights.append({"type": "laser", "power": 1}), r"light 0.*unknown type"),
    (lambda s: s.lights.append({"type": "point"}), r"light 0 \(point\): missing 'power'"),
    (lambda s: s.lights.append({"type": "sun", "power": 1}), r"missing 'strength'"),
    (lambda s: s.lights.append({"type": "area", "power": 1, "shape": "star"}), r"shape"),
    (lambda s: s.lights.append({"type": "area", "power": 1, "size": [0, 1]}), r"size"),
    (lambda s: s.lights.append({"type": "spot", "power": 1, "spot_size": 4.0}), r"spot_size"),
])
def test_scene_validation_messages(mutate, message):
    scene = one_triangle_scene()
    mutate(scene)
    with pytest.raises(ValueError, match=message):
        scene.validate()


def test_light_defaults():
    scene = Scene()
    scene.add_light("point", power=100)
    scene.add_light("sun", strength=[1, 2, 3])
    scene.add_light("area", power=10)
    scene.add_light("spot", power=10)
    point, sun, area, spot = scene.validate().lights
    assert point["power"] == [100.0] * 3 and point["radius"] == 0.0
    assert point["visible_camera"] is False  # Blender 5.0's default for lights
    assert sun["strength"] == [1.0, 2.0, 3.0] and sun["direction"] == [0.0, 0.0, -1.0]
    assert area["shape"] == "square" and area["size"] == [1.0, 1.0]
    assert 0 < spot["spot_size"] <= np.pi


def assert_scenes_equal(a, b):
    assert a.film == b.film and a.camera == b.camera and a.world == b.world
    assert a.materials == b.materials and a.lights == b.lights
    assert len(a.meshes) == len(b.meshes)
    for ma, mb in zip(a.meshes, b.meshes):
        assert set(ma) == set(mb)
        for key in ma:
            if isinstance(ma[key], np.ndarray):
                assert ma[key].dtype == mb[key].dtype and ma[key].shape == mb[key].shape
                assert np.array_equal(ma[key], mb[key], equal_nan=True), key
            else:
                assert ma[key] == mb[key], key


def test_save_load_round_trip_exact(tmp_path):
    scene = scenes.cornell_box(width=40, height=30)
    rng = np.random.default_rng(3)
    v = scene.meshes[0]["positions"].shape[0]
    scene.meshes[0]["normals"] = rng.standard_normal((v, 3)).astype(np.float32)
    scene.meshes[0]["uvs"] = rng.random((v, 2)).astype(np.float32)
    scene.meshes[1]["positions"][0, 0] = np.nan
    scene.camera["screen"] = [-0.1234567890123, 0.3, -0.2, 1 / 3]
    scene.world["color"] = [0.1, 0.2, 1e-30]
    scene.add_light("sun", strength=[3, 2, 1], direction=[0.1, 0.2, -1.0], angle=0.01)
    scene.validate()
    path = tmp_path / "box.lantern"
    scene.save(path)
    loaded = load_scene(path)
    assert_scenes_equal(scene, loaded)
    # and again: saving what was loaded writes the same content
    path2 = tmp_path / "box2.lantern"
    loaded.save(path2)
    assert_scenes_equal(scene, load_scene(path2))


def test_file_layout(tmp_path):
    path = tmp_path / "f.lantern"
    scenes.furnace_sphere(subdivisions=1).save(path)
    with zipfile.ZipFile(path) as zf:
        doc = json.loads(zf.read("scene.json"))
        assert doc["format"] == "lantern-scene" and doc["version"] == FORMAT_VERSION
        assert doc["meshes"][0]["positions"] == "meshes/0/positions.npy"
        assert doc["meshes"][0]["normals"] is None
        assert all(i.compress_type == zipfile.ZIP_DEFLATED for i in zf.infolist())
        arr = np.load(io.BytesIO(zf.read("meshes/0/indices.npy")))
        assert arr.dtype == np.uint32


def rewrite_json(path, out, change):
    with zipfile.ZipFile(path) as zf:
        members = {n: zf.read(n) for n in zf.namelist()}
    doc = json.loads(members["scene.json"])
    change(doc)
    members["scene.json"] = json.dumps(doc).encode()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zf:
        for n, data in members.items():
            zf.writestr(n, data)


def test_refuses_newer_major_version(tmp_path):
    path = tmp_path / "a.lantern"
    one_triangle_scene().save(path)
    newer = tmp_path / "newer.lantern"
    rewrite_json(path, newer, lambda d: d.update(version=2))
    with pytest.raises(ValueError, match=r"version 2 is newer.*update Lantern"):
        load_scene(newer)
    rewrite_json(path, newer, lambda d: d.update(version="3.1"))
    with pytest.raises(ValueError, match="newer"):
        load_scene(newer)
    minor = tmp_path / "minor.lantern"
    rewrite_json(path, minor, lambda d: d.update(version="1.4"))
    assert len(load_scene(minor).meshes) == 1


def test_refuses_other_files(tmp_path):
    not_zip = tmp_path / "x.lantern"
    not_zip.write_text("hello")
    with pytest.raises(ValueError, match="not a Lantern scene file"):
        load_scene(not_zip)
    no_json = tmp_path / "y.lantern"
    with zipfile.ZipFile(no_json, "w") as zf:
        zf.writestr("other.txt", "x")
    with pytest.raises(ValueError, match="no scene.json"):
        load_scene(no_json)
    path = tmp_path / "a.lantern"
    one_triangle_scene().save(path)
    other = tmp_path / "other.lantern"
    rewrite_json(path, other, lambda d: d.update(format="gltf"))
    with pytest.raises(ValueError, match="not a Lantern scene file"):
        load_scene(other)
    missing = tmp_path / "missing.lantern"
    rewrite_json(path, missing,
                 lambda d: d["meshes"][0].update(positions="meshes/9/positions.npy"))
    with pytest.raises(ValueError, match="mesh 0 positions.*missing"):
        load_scene(missing)
    with pytest.raises(FileNotFoundError):
        load_scene(tmp_path / "nope.lantern")


def test_icosphere_is_closed():
    pos, idx = scenes.icosphere(2)
    assert idx.shape == (20 * 16, 3)
    assert np.allclose(np.linalg.norm(pos, axis=1), 1.0, atol=1e-6)
    edges = {}
    for tri in idx.tolist():
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    # watertight and consistently wound: every directed edge once, its reverse once
    assert all(n == 1 for n in edges.values())
    assert all((b, a) in edges for a, b in edges)
    # counter-clockwise seen from outside: normals point away from the centre
    v = pos[idx]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    assert (np.einsum("ij,ij->i", n, v.mean(axis=1)) > 0).all()


def test_builders_validate():
    f = scenes.furnace_sphere(albedo=0.5, emission=2.0, subdivisions=2, width=8, height=6)
    f.validate()
    assert f.film["width"] == 8 and f.materials[0]["emission"] == [2.0] * 3
    c = scenes.cornell_box(width=32, height=32)
    assert c.validate().lights[0]["type"] == "area"
    assert c.triangle_count == 10 + 24
    s = scenes.integrating_sphere(light="sphere", light_radius=0.1, subdivisions=1)
    assert s.validate().lights[0]["radius"] == 0.1
    with pytest.raises(ValueError):
        scenes.integrating_sphere(light="laser")


def test_expected_values():
    assert np.allclose(scenes.furnace_expected(1.0, 0.5, 1), 1.0)
    assert np.allclose(scenes.furnace_expected(1.0, 0.5, 3), 1.75)
    assert np.allclose(scenes.furnace_expected(2.0, 0.5, 200), 4.0)
    # direct only (depth 2): (a / pi) * P / (4 pi R^2)
    e = scenes.integrating_sphere_expected(0.5, 4 * np.pi ** 2, 1.0, 2)
    assert np.allclose(e, 0.5)
    assert np.allclose(scenes.integrating_sphere_expected(0.5, 4 * np.pi ** 2, 1.0, 1), 0.0)


def test_thin_film_fields(tmp_path):
    """Thin film: validated ranges, carried by the file, finite renders for hostile values that
    reach the native core directly (NaN, negative, infinite, huge)."""
    s = Scene()
    for bad in (float("nan"), -1.0, 2e5):
        with pytest.raises(ValueError, match="thin_film_thickness"):
            s.add_material(type="principled", thin_film_thickness=bad)
    with pytest.raises(ValueError, match="thin_film_ior"):
        s.add_material(type="principled", thin_film_ior=0.5)
    scene = scenes.cornell_box(16, 16)
    m = scene.add_material("film", type="principled", base_color=(0.05, 0.05, 0.05),
                           roughness=0.2, thin_film_thickness=500.0, thin_film_ior=1.33)
    scene.meshes[-1]["material_ids"][:] = m   # the tall box
    path = tmp_path / "film.lantern"
    scene.save(path)
    back = load_scene(path)
    assert back.materials[m]["thin_film_thickness"] == 500.0
    assert back.materials[m]["thin_film_ior"] == 1.33
    film = lantern.render(scene, spp=8, seed=2, threads=2, integrator="pt")
    assert np.isfinite(film).all()
    from lantern import _core
    from lantern.session import resolve_settings
    settings = dict(resolve_settings(dict(seed=2, threads=2, spp_per_iteration=8))[0])
    for bad in (float("nan"), -3.0, float("inf"), 1e9):
        native = scene.to_native()   # past the Python validation: the core clamps
        native["materials"][m]["thin_film_thickness"] = bad
        native["materials"][m]["thin_film_ior"] = bad
        session = _core.Session(native, settings)
        session.step()
        assert np.isfinite(np.asarray(session.image())).all(), bad
