"""Image textures, normal maps and alpha through the native core, against analytic images.

A plane under a constant white world reflects exactly its albedo (it sees only the sky), so a
textured diffuse plane must render its texture; under a sun, a normal-mapped diffuse plane
reflects albedo/pi E cos(mapped normal, sun).

Noise-free cases (pt on a sunlit plane: one delta light, nothing else to hit) are checked per
pixel to 1e-4; noisy ones through lantern.metrics.assert_agreement against the exact value with
its negative controls (tests/README.md: K seeds, bias cap 1e-4 for an exact value)."""
import math

import numpy as np
import pytest

import lantern
from lantern import metrics

pytestmark = pytest.mark.usefixtures("core")


def srgb_to_linear(c):
    c = np.asarray(c, np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def plane_scene(size=64, world=1.0):
    """An orthographic view from above of the square [-1, 1]^2 at z = 0 (image up = +y), under
    a constant world; finish_plane adds the plane itself."""
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.camera.update(type="orthographic", screen=[-1.0, 1.0, -1.0, 1.0],
                    to_world=[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5], [0, 0, 0, 1]])
    s.world["color"] = [world] * 3
    return s


def finish_plane(s, material, tangents=None):
    """The 2 m square, uv (0, 0) at its lower-left corner, of a diffuse `material` dict."""
    m = s.add_material(type="diffuse", **material)
    pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    s.add_mesh(pos, [[0, 1, 2], [0, 2, 3]], material=m, uvs=uvs,
               normals=np.tile([0, 0, 1], (4, 1)).astype(np.float32), tangents=tangents)
    return s


def block_z(img, expected, rows, cols):
    """|z| of the block mean of img[rows, cols] against `expected` per channel, the standard
    error from the pixels' own spread (the true value is constant over the block)."""
    block = img[rows, cols].reshape(-1, 3).astype(np.float64)
    se = block.std(axis=0, ddof=1) / math.sqrt(block.shape[0])
    se = np.maximum(se, 1e-6 * np.abs(expected) + 1e-9)
    return np.abs(block.mean(axis=0) - expected) / se


CHECKER = np.array([[[200, 30, 10, 255], [10, 180, 60, 255], [0, 0, 0, 255], [255, 255, 255, 255]],
                    [[90, 90, 90, 255], [255, 0, 128, 255], [40, 200, 220, 255], [128, 128, 0, 255]],
                    [[5, 5, 250, 255], [250, 250, 5, 255], [60, 60, 60, 255], [120, 20, 200, 255]],
                    [[33, 66, 99, 255], [99, 66, 33, 255], [180, 180, 180, 255], [1, 2, 3, 255]]],
                   np.uint8)


K = 16   # seeds of the statistical comparisons (Welch dof 15)
EXACT = 1e-4


def assert_exact(img, expected, name):
    """Noise-free by construction: every pixel within EXACT (relative) of the expected value."""
    img = np.asarray(img, np.float64)
    err = np.abs(img - expected) / np.maximum(np.abs(expected), 1e-3)
    assert err.max() <= EXACT, (name, float(err.max()), img.reshape(-1, 3).mean(axis=0),
                                expected)


def interior_mask(grid, texels, margin):
    """(grid, grid) block mask: the blocks at least `margin` blocks inside each of the
    texels x texels equal cells (the pixel filter blurs across the cell edges)."""
    cell = grid // texels
    inner = np.zeros(cell, bool)
    inner[margin:cell - margin] = True
    row = np.tile(inner, texels)
    return row[:, None] & row[None, :]


@pytest.mark.parametrize("colorspace", ["srgb", "linear"])
@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_textured_plane_renders_its_texture(colorspace, integrator, backend):
    s = plane_scene()
    tex = s.add_texture(CHECKER, colorspace=colorspace, interpolation="closest")
    finish_plane(s, dict(base_color_texture=tex))
    imgs = [lantern.render(s, spp=16, integrator=integrator, seed=3 + k, threads=2,
                           backend=backend) for k in range(K)]
    assert np.isfinite(np.stack(imgs)).all()
    expected_all = CHECKER[..., :3] / 255.0
    if colorspace == "srgb":
        expected_all = srgb_to_linear(expected_all)
    # texel (tx, ty) covers pixels x in [16 tx, 16 tx + 16), image rows from the top
    expected = np.repeat(np.repeat(expected_all[::-1], 16, axis=0), 16, axis=1)
    # 4x4 blocks: the two inside each texel's 16 x 16 pixels on each axis
    metrics.assert_agreement(f"checker {colorspace} {integrator}", imgs, expected, block=4,
                             mask=interior_mask(16, 4, 1), bias_cap=EXACT)


def test_bilinear_ramp_and_wrap_modes(backend):
    # two linear texels 0 and 255: bilinear filtering is the straight line between the texel
    # centres (u = 0.25 and 0.75); a symmetric pixel filter keeps a linear function's value
    ramp = np.array([[[0, 0, 0, 255], [255, 255, 255, 255]]], np.uint8)
    u = (np.arange(64) + 0.5) / 64                          # column centres
    line = (u - 0.25) / 0.5
    expected = {"extend": np.clip(line, 0.0, 1.0), "mirror": np.clip(line, 0.0, 1.0),
                # past a centre, repeat blends with the texel on the other side
                "repeat": np.where(u < 0.25, 0.5 - 2 * u, np.where(u > 0.75, 2.5 - 2 * u, line))}
    for wrap, exp in expected.items():
        s = plane_scene()
        tex = s.add_texture(ramp, colorspace="linear", wrap=wrap)
        finish_plane(s, dict(base_color_texture=tex))
        img = lantern.render(s, spp=16, integrator="pt", seed=5, threads=2, backend=backend)
        cols = img[8:56, 2:62, 0].astype(np.float64)  # the outer columns also see the sky
        se = cols.std(axis=0, ddof=1) / math.sqrt(cols.shape[0]) + 1e-4
        z = np.abs(cols.mean(axis=0) - exp[2:62]) / se
        # the filter (1.5 px wide) averages across the kinks at the texel centres: compare
        # only the columns whose filter support stays on one linear piece
        x = np.arange(2, 62) + 0.5
        z[(np.abs(x - 16) < 1.5) | (np.abs(x - 48) < 1.5)] = 0.0
        assert z.max() < 4.5, (wrap, z.max(), int(z.argmax()) + 2)
    # 8-bit sRGB is filtered encoded and decoded afterwards, as Cycles does: halfway between
    # black and white texels is decode(0.5) = 0.214, not 0.5
    s = plane_scene()
    tex = s.add_texture(ramp, colorspace="srgb", wrap="extend")
    finish_plane(s, dict(base_color_texture=tex))
    img = lantern.render(s, spp=16, integrator="pt", seed=5, threads=2, backend=backend)
    cols = img[8:56, 2:62, 0].astype(np.float64)
    se = cols.std(axis=0, ddof=1) / math.sqrt(cols.shape[0]) + 1e-4
    exp = srgb_to_linear(np.clip(line, 0.0, 1.0))[2:62]
    z = np.abs(cols.mean(axis=0) - exp) / se
    x = np.arange(2, 62) + 0.5
    z[(np.abs(x - 16) < 1.5) | (np.abs(x - 48) < 1.5)] = 0.0  # the kinks, as above
    assert z.max() < 4.5, ("srgb", z.max(), int(z.argmax()) + 2)
    mid = cols[:, 29:31].mean()                  # u about 0.5: decode(0.5) = 0.214
    # (the z-test above checks every column against decode(line); this names the point)
    assert abs(mid - 0.214) < 0.03 and abs(mid - 0.5) > 0.2, mid
    # clip: outside [0, 1] transparent black; a uv transform scaling by 2 shows it on 3/4
    s = plane_scene()
    white = np.full((1, 1, 4), 255, np.uint8)
    tex = s.add_texture(white, colorspace="linear", wrap="clip", interpolation="closest",
                        uv_transform=[[2.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    finish_plane(s, dict(base_color_texture=tex))
    img = lantern.render(s, spp=8, integrator="pt", seed=5, threads=2, backend=backend)
    # lower-left quarter: uv' in [0, 1], white (albedo 1 under the white world)
    assert block_z(img, np.ones(3), slice(40, 60), slice(4, 28)).max() < 5.0
    assert img[4:28, 4:60].max() <= EXACT       # upper half: v' > 1, black
    assert img[36:60, 36:60].max() <= EXACT     # lower-right: u' > 1


def sun_scene(n_ts_bytes, tangents=None, integrator="pt", seed=1, spp=16):
    s = plane_scene(world=0.0)
    if all(isinstance(v, int) for v in n_ts_bytes):
        nmap = np.array([[list(n_ts_bytes) + [255]]], np.uint8)
    else:  # float texels (scene linear, as Non-Color)
        nmap = np.array([[list(n_ts_bytes) + [1.0]]], np.float32)
    tex = s.add_texture(nmap, colorspace="linear", interpolation="closest")
    finish_plane(s, dict(base_color=[0.5, 0.5, 0.5], normal_texture=tex), tangents)
    # the sun shines from +x, 45 degrees up
    s.add_light("sun", strength=[2.0, 2.0, 2.0], direction=[-1.0, 0.0, -1.0])
    return lantern.render(s, spp=spp, integrator=integrator, seed=seed, threads=2)


def bump_shadowing(n, light):
    """Cycles' bump shadowing term on a diffuse lobe whose normal n a map tilts off the plane's
    own normal +z (docs/nodes.md "Bump and displacement"): the GGX masking G1 with alpha^2 =
    tan^2(tilt) / 8 at the light's angle to +z (Conty Estevez et al., Ray Tracing Gems 2019)."""
    alpha2 = min(math.tan(math.acos(n[2])) ** 2 / 8.0, 1.0)
    return 2.0 / (1.0 + math.sqrt(1.0 + alpha2 * math.tan(math.acos(light[2])) ** 2))


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_normal_map_tilts_shading_normal(integrator):
    b = (int(round((math.sin(math.radians(30)) + 1) * 127.5)), 128,
         int(round((math.cos(math.radians(30)) + 1) * 127.5)))
    n = np.array([2 * v / 255.0 - 1 for v in b])
    n /= np.linalg.norm(n)               # tangent +u = world +x, bitangent +v = world +y
    light = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    # the cosine of the mapped normal, times Cycles' bump shadowing (0.9898 here)
    expected = 0.5 / math.pi * 2.0 * max(0.0, float(n @ light)) * bump_shadowing(n, light)
    flat = 0.5 / math.pi * 2.0 * light[2]
    assert abs(expected - flat) > 0.05 * flat  # the test can tell them apart
    check_sun_plane(b, expected, integrator, "tilted")
    # explicit MikkTSpace-style tangents (+x, sign +1) give the same; a mirrored tangent
    # (-x, sign -1) flips the tilt
    t = np.tile([1.0, 0.0, 0.0, 1.0], (4, 1)).astype(np.float32)
    check_sun_plane(b, expected, integrator, "tangent +x", tangents=t)
    t_flip = np.tile([-1.0, 0.0, 0.0, -1.0], (4, 1)).astype(np.float32)
    n_f = np.array([-n[0], n[1], n[2]])
    exp_f = 0.5 / math.pi * 2.0 * max(0.0, float(n_f @ light)) * bump_shadowing(n_f, light)
    check_sun_plane(b, exp_f, integrator, "tangent -x", tangents=t_flip)


def check_sun_plane(texel, expected, integrator, name, tangents=None):
    """The sunlit normal-mapped plane's pixels [8:56, 8:56] against their constant value: pt
    sees only the sun (noise-free, per pixel to 1e-4); cis also splats light paths (noisy: K
    seeds through assert_agreement, the blocks inside that square)."""
    if integrator == "pt":
        img = sun_scene(texel, tangents=tangents, integrator="pt")
        assert_exact(img[8:56, 8:56], expected, name)
        return
    imgs = [sun_scene(texel, tangents=tangents, integrator=integrator, seed=10 + k, spp=4)
            for k in range(K)]
    mask = np.zeros((8, 8), bool)
    mask[1:7, 1:7] = True
    metrics.assert_agreement(f"normal map {name} {integrator}", imgs,
                             np.full((64, 64, 3), expected), block=8, mask=mask,
                             bias_cap=EXACT)


def test_normal_map_bad_values_stay_finite():
    # 0.5 grey maps to the zero vector, (0, 0, 0) and (128, 128, 0) point below the surface,
    # NaN texels (read as 0): all keep the unperturbed normal
    flat = 0.5 / math.pi * 2.0 / math.sqrt(2)
    for b in ((0.5, 0.5, 0.5), (0, 0, 0), (128, 128, 0), (float("nan"),) * 3):
        img = sun_scene(b)
        assert np.isfinite(img).all()
        assert_exact(img[8:56, 8:56], flat, b)


def test_float_texture_with_nan_and_bad_uvs():
    s = plane_scene()
    px = np.full((2, 2, 4), 0.5, np.float32)
    px[0, 0, :3] = np.nan
    px[1, 1, 0] = np.inf
    tex = s.add_texture(px, interpolation="closest")
    finish_plane(s, dict(base_color_texture=tex))
    s.meshes[0]["uvs"] = np.array([[np.nan, 0], [1e30, 0], [1, -1e30], [0, 1]], np.float32)
    session = lantern.Session(s, seed=1, threads=2, integrator="pt")
    session.step()
    img = session.image()
    assert np.isfinite(img).all()
    assert any("non-finite texel" in w for w in session.warnings)


def test_texture_validation_errors():
    s = lantern.Scene()
    with pytest.raises(ValueError, match="pixels"):
        s.add_texture(np.zeros((4, 4), np.uint8))
    with pytest.raises(ValueError, match="wrap"):
        s.add_texture(np.zeros((4, 4, 4), np.uint8), wrap="tile")
    with pytest.raises(ValueError, match="out of range"):
        s.add_material(base_color_texture=0)
    t = s.add_texture(np.zeros((4, 4, 3), np.uint8))
    assert s.textures[t]["pixels"].shape == (4, 4, 4)
    with pytest.raises(TypeError):
        s.add_material(colour_texture=t)


def test_scene_file_carries_textures(tmp_path):
    s = plane_scene(size=32)
    tex = s.add_texture(CHECKER, colorspace="srgb", wrap="mirror", interpolation="closest",
                        uv_transform=[[2.0, 0.0, 0.1], [0.0, 2.0, 0.0]])
    ftex = s.add_texture(np.random.default_rng(1).random((3, 5, 4)).astype(np.float32))
    finish_plane(s, dict(base_color_texture=tex, roughness_texture=ftex))
    path = tmp_path / "textured.lantern"
    s.save(path)
    back = lantern.load_scene(path)
    assert len(back.textures) == 2
    assert back.textures[0]["pixels"].dtype == np.uint8
    assert np.array_equal(back.textures[0]["pixels"], s.textures[0]["pixels"])
    assert np.array_equal(back.textures[1]["pixels"], s.textures[1]["pixels"])
    assert back.textures[0]["wrap"] == "mirror"
    assert back.materials[0]["base_color_texture"] == 0
    a = lantern.render(s, spp=4, seed=9, threads=1, integrator="pt")
    b = lantern.render(back, spp=4, seed=9, threads=1, integrator="pt")
    assert np.array_equal(a, b)


ALPHA_SPP = 4   # x K seeds, the old single render's 64: pt resolves 0.63 % (0.89 % at 2)


def alpha_card_scene(a):
    """A red diffuse card of alpha a, 0.5 m over a grey diffuse floor, under a sun from +x 45
    degrees up, seen from above (plane_scene's view, no world)."""
    s = plane_scene(world=0.0)
    floor = s.add_material(base_color=[0.5, 0.5, 0.5])
    card = s.add_material(base_color=[0.8, 0.1, 0.1], alpha=a)
    quad = [[0, 1, 2], [0, 2, 3]]
    s.add_mesh(np.array([[-9, -9, 0], [9, -9, 0], [9, 9, 0], [-9, 9, 0]], np.float32), quad,
               material=floor)
    # the card: x in [-1, 0], 0.5 m above the floor; the sun from +x 45 degrees up shadows
    # x in [-1.5, -0.5] of the floor
    s.add_mesh(np.array([[-1, -1, 0.5], [0, -1, 0.5], [0, 1, 0.5], [-1, 1, 0.5]], np.float32),
               quad, material=card)
    s.add_light("sun", strength=[2.0, 2.0, 2.0], direction=[-1.0, 0.0, -1.0])
    return s


def alpha_card_expected(a):
    """alpha_card_scene's exact image (direct light only) and the mask of its 4 x 4 blocks of
    rows 8:56 whose columns keep 1.5 px (the filter) from every edge."""
    e = 2.0 / math.sqrt(2)                 # irradiance of the sun at 45 degrees
    lit_floor = 0.5 / math.pi * e
    card_l = np.array([0.8, 0.1, 0.1]) / math.pi * e
    # by column (x of column i's centre: (i + 0.5) / 32 - 1)
    expected = np.zeros((64, 64, 3))
    # card over shadowed floor (x in [-1, -0.5], columns 0-15): a card + (1 - a) floor seen
    # through it, itself lit by the (1 - a) of the sun that passes the card
    expected[:, 0:16] = a * card_l + (1 - a) * (1 - a) * lit_floor
    # card over lit floor (x in [-0.5, 0], columns 16-31)
    expected[:, 16:32] = a * card_l + (1 - a) * lit_floor
    # open floor (x > 0, columns 32-63)
    expected[:, 32:64] = lit_floor
    mask = np.zeros((16, 16), bool)
    for cols in (slice(1, 3), slice(5, 7), slice(9, 15)):   # columns 4-11, 20-27, 36-59
        mask[2:14, cols] = True
    return expected, mask


@pytest.mark.parametrize("integrator", ["pt", "bdpt", "cis"])
def test_alpha_coverage(integrator, backend):
    """A red diffuse card of alpha a over a white diffuse floor under a sun, seen from above:
    each pixel of the card region is a mix a L_card + (1 - a) L_floor_behind, and the floor
    beside the card is lit through it: (1 - a) of the sun reaches the shadowed floor. All
    expected values analytic (sun 45 degrees, direct light only: max_depth 2): K seeds against
    them with assert_agreement and its 1 % / 5 % negative controls (it was z < 5 on one
    render's pixel spread, no control)."""
    a = 0.3
    s = alpha_card_scene(a)
    imgs = [lantern.render(s, spp=ALPHA_SPP, integrator=integrator, seed=2 + k, threads=2,
                           max_depth=2, backend=backend) for k in range(K)]
    assert np.isfinite(np.stack(imgs)).all()
    expected, mask = alpha_card_expected(a)
    metrics.assert_agreement(f"alpha coverage {integrator}", imgs, expected, block=4,
                             mask=mask, bias_cap=EXACT)


def test_alpha_texture_cuts_out(backend):
    """An alpha-textured card (left texel alpha 0, right 255, closest) over a sunlit floor:
    the left half is absent for every ray (floor lit, no shadow), the right half opaque."""
    s = plane_scene(world=0.0)
    tex = s.add_texture(np.array([[[9, 9, 9, 0], [9, 9, 9, 255]]], np.uint8),
                        interpolation="closest", output="alpha")
    floor = s.add_material(base_color=[0.5, 0.5, 0.5])
    card = s.add_material(base_color=[0.8, 0.1, 0.1], alpha_texture=tex)
    quad = [[0, 1, 2], [0, 2, 3]]
    s.add_mesh(np.array([[-9, -9, 0], [9, -9, 0], [9, 9, 0], [-9, 9, 0]], np.float32), quad,
               material=floor)
    s.add_mesh(np.array([[-1, -1, 0.5], [1, -1, 0.5], [1, 1, 0.5], [-1, 1, 0.5]], np.float32),
               quad, material=card, uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32))
    s.add_light("sun", strength=[2.0, 2.0, 2.0], direction=[0.0, 0.0, -1.0])
    img = lantern.render(s, spp=16, integrator="cis", seed=2, threads=2, max_depth=2,
                         backend=backend)
    # nearly noise-free (a few pixels of cis's light-path splats differ by < 1e-3; the region
    # means by ~2e-6): the region means exact to 1e-4
    np.testing.assert_allclose(img[8:56, 4:28].mean(axis=(0, 1)), 0.5 / math.pi * 2.0,
                               rtol=EXACT)
    np.testing.assert_allclose(img[8:56, 36:60].mean(axis=(0, 1)),
                               np.array([0.8, 0.1, 0.1]) / math.pi * 2.0, rtol=EXACT)


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_emission_texture_seen_directly(integrator, backend):
    """An emission-textured plane in a black world shows texel x multiplier."""
    s = plane_scene(world=0.0)
    tex = s.add_texture(CHECKER, colorspace="srgb", interpolation="closest")
    finish_plane(s, dict(base_color=[0.0, 0.0, 0.0], emission=[2.0, 1.0, 0.5],
                         emission_texture=tex))
    img = lantern.render(s, spp=8, integrator=integrator, seed=1, threads=2, backend=backend)
    expected_all = srgb_to_linear(CHECKER[..., :3] / 255.0) * [2.0, 1.0, 0.5]
    for ty in range(4):
        for tx in range(4):
            block = img[64 - 16 * (ty + 1) + 4:64 - 16 * ty - 4, 16 * tx + 4:16 * tx + 12]
            np.testing.assert_allclose(block.reshape(-1, 3).mean(axis=0), expected_all[ty, tx],
                                       rtol=1e-4, atol=1e-6)


def _lit_floor(emitter):
    """A diffuse floor under a downward-facing emissive quad at z = 1 (x in [-0.5, 0.5])."""
    s = lantern.Scene()
    s.film.update(width=32, height=32)
    s.camera.update(type="orthographic", screen=[-2.0, 2.0, -2.0, 2.0],
                    to_world=[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5], [0, 0, 0, 1]])
    floor = s.add_material(base_color=[0.6, 0.6, 0.6])
    s.add_mesh(np.array([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], np.float32),
               [[0, 1, 2], [0, 2, 3]], material=floor)
    emitter(s)
    return s


def _textured_emitter(s):
    """A quad emitter whose texture is white on its left half, black on its right."""
    tex = s.add_texture(np.array([[[255, 255, 255, 255], [0, 0, 0, 255]]], np.uint8),
                        colorspace="linear", interpolation="closest")
    m = s.add_material(base_color=[0, 0, 0], emission=[3.0] * 3, emission_texture=tex)
    s.add_mesh(np.array([[-0.5, -0.5, 1], [-0.5, 0.5, 1], [0.5, 0.5, 1], [0.5, -0.5, 1]],
                        np.float32), [[0, 1, 2], [0, 2, 3]], material=m,
               uvs=np.array([[0, 0], [0, 1], [1, 1], [1, 0]], np.float32),
               visible_camera=False)


def _half_emitter(s):
    """The constant emitter of that quad's left half alone."""
    m = s.add_material(base_color=[0, 0, 0], emission=[3.0] * 3)
    s.add_mesh(np.array([[-0.5, -0.5, 1], [-0.5, 0.5, 1], [0.0, 0.5, 1], [0.0, -0.5, 1]],
                        np.float32), [[0, 1, 2], [0, 2, 3]], material=m,
               visible_camera=False)


def test_emission_texture_lights_like_its_bright_part():
    """A quad emitter whose texture is white on its left half and black on its right lights a
    floor as a constant emitter of the left half alone (pt, bdpt, cis agree with that)."""
    # the floor's noise at this cost resolves a whole-image bias of ~2 % with 16 x 24 spp a
    # side: 32 seeds, the shared reference at twice the samples (about 0.95 %)
    ref = [lantern.render(_lit_floor(_half_emitter), spp=96, integrator="pt", seed=100 + k,
                          threads=2, max_depth=2) for k in range(2 * K)]
    for integrator in ("pt", "bdpt", "cis"):
        got = [lantern.render(_lit_floor(_textured_emitter), spp=48, integrator=integrator,
                              seed=200 + k, threads=2, max_depth=2) for k in range(2 * K)]
        metrics.assert_agreement(f"textured emitter {integrator} vs half emitter pt", got, ref,
                                 block=8)


def coat_plane(coat_map=None, base_map=None, integrator="pt", seed=3, spp=16):
    """A plane whose only lobe is a rough coat (black base, Specular IOR Level 0) under a sun
    from +x, 45 degrees up, and a grey world; normal maps as RGB texels (ints: uint8, else
    float). The image's plane square [8:56, 8:56] (float64)."""
    def texture(s, texel):
        if all(isinstance(v, int) for v in texel):
            return s.add_texture(np.array([[list(texel) + [255]]], np.uint8),
                                 colorspace="linear", interpolation="closest")
        return s.add_texture(np.array([[list(texel) + [1.0]]], np.float32),
                             interpolation="closest")
    s = plane_scene(world=0.3)
    mat = dict(type="principled", base_color=[0.0, 0.0, 0.0], specular_level=0.0,
               coat_weight=1.0, coat_roughness=0.3)
    if coat_map is not None:
        mat["coat_normal_texture"] = texture(s, coat_map)
    if base_map is not None:
        mat["normal_texture"] = texture(s, base_map)
    m = s.add_material(**mat)
    pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    s.add_mesh(pos, [[0, 1, 2], [0, 2, 3]], material=m, uvs=uvs,
               normals=np.tile([0, 0, 1], (4, 1)).astype(np.float32))
    s.add_light("sun", strength=[2.0, 2.0, 2.0], direction=[-1.0, 0.0, -1.0])
    img = lantern.render(s, spp=spp, integrator=integrator, seed=seed, threads=2)
    assert np.isfinite(img).all()
    return np.asarray(img[8:56, 8:56], np.float64)


COAT_TILT = (int(round((math.sin(math.radians(30)) + 1) * 127.5)), 128,
             int(round((math.cos(math.radians(30)) + 1) * 127.5)))


@pytest.mark.parametrize("integrator", ["pt", "bdpt", "cis"])
def test_coat_normal_equals_coat_on_mapped_normal(integrator):
    """With the coat the only lobe, a coat whose own normal is tilted (flat shading normal for
    the integrator, the coat in its own frame: per-lobe cosines and adjoint factors) renders what
    the same coat renders on a base normal mapped the same way (one frame for everything), and
    clearly not what the untilted coat renders. With the same seed both trace the same paths
    (measured: the same image to 1.7e-7), so per pixel to 1e-4, no statistics (tests/README.md,
    noise-free); it was the two images' means over 4 seeds each within 6 se, no control."""
    own = coat_plane(coat_map=COAT_TILT, integrator=integrator)
    both = coat_plane(coat_map=COAT_TILT, base_map=COAT_TILT, integrator=integrator)
    flat = coat_plane(integrator=integrator)
    err = np.abs(own - both) / np.maximum(np.abs(both), 1e-3)
    print(f"{integrator}: own coat normal {own.mean():.5f}, coat on the mapped normal "
          f"{both.mean():.5f} (worst pixel {err.max():.2e}), untilted {flat.mean():.5f}")
    assert err.max() <= EXACT, err.max()
    # the test can fail: the untilted coat differs by far more than 1e-4
    assert abs(own.mean() - flat.mean()) > 0.1 * flat.mean()


def test_coat_normal_bad_input():
    s = lantern.Scene()
    with pytest.raises(ValueError, match="coat_normal_strength"):
        s.add_material(type="principled", coat_weight=1.0, coat_normal_strength=float("nan"))
    with pytest.raises(ValueError, match="out of range"):
        s.add_material(type="principled", coat_weight=1.0, coat_normal_texture=3)
    # degenerate maps (0.5 grey: the zero vector; below the surface; NaN) keep the smooth
    # normal: the same seed renders the untilted coat's bits (was its mean within 6 se)
    flat = coat_plane(seed=6)
    for texel in ((0.5, 0.5, 0.5), (128, 128, 0), (0, 0, 0), (float("nan"),) * 3):
        np.testing.assert_array_equal(coat_plane(coat_map=texel, seed=6), flat, err_msg=texel)
