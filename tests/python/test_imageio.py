"""Image I/O through OpenImageIO and through the built-in fallback, crossed both ways."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lantern import imageio

BACKENDS = ["oiio", "builtin"]
BITTERLI = sorted(Path("/work/shared/scenes/bitterli").glob("*/TungstenRender.exr"))


def have_oiio():
    try:
        import OpenImageIO  # noqa: F401
    except ImportError:
        return False
    return True


def backends():
    return [pytest.param(b, marks=pytest.mark.skipif(b == "oiio" and not have_oiio(),
                                                    reason="OpenImageIO not installed"))
            for b in BACKENDS]


@pytest.fixture
def image():
    rng = np.random.default_rng(7)
    img = (rng.random((37, 53, 3)) * 20.0 - 2.0).astype(np.float32)
    img[0, 0] = [np.inf, -0.0, 1e-40]  # infinities, signed zero and denormals survive
    img[1, 1] = [65504.0, 1e6, -1e-8]
    return img


@pytest.mark.parametrize("writer", backends())
@pytest.mark.parametrize("reader", backends())
@pytest.mark.parametrize("compression", ["none", "zip", "zips"])
def test_exr_float_exact(tmp_path, image, writer, reader, compression):
    path = tmp_path / "img.exr"
    imageio.write_image(path, image, compression=compression, backend=writer)
    back = imageio.read_image(path, backend=reader)
    assert back.dtype == np.float32 and back.shape == image.shape
    assert np.array_equal(back, image)
    assert np.array_equal(np.signbit(back), np.signbit(image))


@pytest.mark.parametrize("writer", backends())
@pytest.mark.parametrize("reader", backends())
def test_exr_half(tmp_path, image, writer, reader):
    path = tmp_path / "img.exr"
    imageio.write_image(path, image, half=True, backend=writer)
    back = imageio.read_image(path, backend=reader)
    with np.errstate(over="ignore"):
        expected = image.astype(np.float16).astype(np.float32)
    assert np.array_equal(back, expected)


@pytest.mark.parametrize("writer", backends())
@pytest.mark.parametrize("reader", backends())
def test_png_srgb(tmp_path, writer, reader):
    ramp = np.linspace(-0.5, 1.5, 64 * 4 * 3, dtype=np.float32).reshape(64, 4, 3)
    path = tmp_path / "img.png"
    imageio.write_image(path, ramp, backend=writer)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    back = imageio.read_image(path, backend=reader)
    clamped = np.clip(ramp, 0, 1)
    # 8-bit sRGB quantisation: at most half a code value in encoded space
    enc_err = np.abs(imageio.srgb_encode(back) - imageio.srgb_encode(clamped))
    assert enc_err.max() <= 0.5 / 255 + 1e-6
    assert back.min() == 0.0 and back.max() == 1.0


def test_png_readers_agree(tmp_path):
    if not have_oiio():
        pytest.skip("OpenImageIO not installed")
    rng = np.random.default_rng(1)
    path = tmp_path / "img.png"
    imageio.write_image(path, rng.random((20, 30, 3)), backend="builtin")
    a = imageio.read_image(path, backend="oiio")
    b = imageio.read_image(path, backend="builtin")
    assert np.array_equal(a, b)


def test_srgb_curve_known_values():
    assert imageio.to_png8(np.array([[[0.0, 1.0, 0.5]]])).tolist() == [[[0, 255, 188]]]
    assert imageio.to_png8(np.array([[[0.0031308, 2.0, -1.0]]])).tolist() == [[[10, 255, 0]]]
    x = np.linspace(0, 1, 101)
    assert np.allclose(imageio.srgb_decode(imageio.srgb_encode(x)), x)


def test_npy(tmp_path, image):
    path = tmp_path / "img.npy"
    imageio.write_image(path, image.astype(np.float64))
    back = imageio.read_image(path)
    assert back.dtype == np.float32 and np.array_equal(back, image)


def test_gray_input_and_errors(tmp_path):
    imageio.write_image(tmp_path / "g.exr", np.ones((4, 5)), backend="builtin")
    assert imageio.read_image(tmp_path / "g.exr", backend="builtin").shape == (4, 5, 3)
    with pytest.raises(ValueError, match="unsupported image extension"):
        imageio.write_image(tmp_path / "x.tif", np.ones((2, 2, 3)))
    with pytest.raises(ValueError, match=r"shape \(H, W, 3\)"):
        imageio.write_image(tmp_path / "x.exr", np.ones((2, 2, 5)))
    with pytest.raises(FileNotFoundError):
        imageio.read_image(tmp_path / "missing.exr")
    (tmp_path / "bad.exr").write_bytes(b"not an exr at all")
    with pytest.raises(ValueError, match="not an OpenEXR file"):
        imageio.read_image(tmp_path / "bad.exr", backend="builtin")


def test_env_var_forces_fallback(tmp_path, monkeypatch, image):
    monkeypatch.setenv("LANTERN_NO_OIIO", "1")
    # OpenImageIO made unimportable: the default path must not need it
    monkeypatch.setitem(sys.modules, "OpenImageIO", None)
    path = tmp_path / "img.exr"
    imageio.write_image(path, image)
    assert np.array_equal(imageio.read_image(path), image)
    imageio.write_image(tmp_path / "img.png", image)


def test_import_does_not_load_oiio():
    code = ("import sys, lantern, lantern.imageio, lantern.metrics, lantern.scenes; "
            "print(sys.modules.get('OpenImageIO') is not None)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


@pytest.mark.skipif(not BITTERLI, reason="no Bitterli reference renders in /work/shared")
@pytest.mark.parametrize("path", BITTERLI, ids=[p.parent.name for p in BITTERLI])
def test_bitterli_references(path):
    # the references are half-float PIZ: OpenImageIO reads them, the fallback says why not
    if have_oiio():
        img = imageio.read_image(path, backend="oiio")
        assert img.ndim == 3 and img.shape[2] == 3 and img.dtype == np.float32
        assert np.isfinite(img).all() and img.mean() > 0
    with pytest.raises(ValueError, match=r"compression PIZ is not supported.*OpenImageIO"):
        imageio.read_image(path, backend="builtin")


@pytest.mark.parametrize("fmt", ["float", "half"])
def test_builtin_reads_rle_written_by_oiio(tmp_path, image, fmt):
    if not have_oiio():
        pytest.skip("OpenImageIO not installed")
    import OpenImageIO as oiio
    image = np.clip(image, -100, 100)
    image[5:20] = 1.0  # long runs
    path = str(tmp_path / "rle.exr")
    spec = oiio.ImageSpec(image.shape[1], image.shape[0], 3, fmt)
    spec.attribute("compression", "rle")
    out = oiio.ImageOutput.create(path)
    assert out.open(path, spec)
    out.write_image(image.astype(np.float16) if fmt == "half" else image)
    out.close()
    expected = imageio.read_image(path, backend="oiio")
    assert np.array_equal(imageio.read_image(path, backend="builtin"), expected)
