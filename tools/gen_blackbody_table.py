"""Writes native/src/scene/blackbody_table.cpp: the blackbody colours that volumes' temperature
grids read (scene/medium_fire.h), the same rows as the Blackbody node's table
(addon/export/node_spectral.py: Planck's law against the CIE 1931 observer, linear Rec.709,
luminance 1, uniform in 1/T over 800-12000 K, not clamped at 0). Run from the repository root:
python3 tools/gen_blackbody_table.py"""
import importlib.util
import pathlib
import sys
import types

root = pathlib.Path(__file__).resolve().parent.parent
pkg = types.ModuleType("export")
pkg.__path__ = [str(root / "addon" / "export")]
sys.modules["export"] = pkg
spectral = importlib.import_module("export.node_spectral")

rows = spectral._blackbody_table()   # 4 floats a row (RGB, 1)
n = len(rows) // 4
assert n == 256
lines = []
for i in range(n):
    r, g, b = rows[4 * i:4 * i + 3]
    lines.append(f"    {r:.8e}f, {g:.8e}f, {b:.8e}f,")
out = root / "native" / "src" / "scene" / "blackbody_table.cpp"
out.write_text(
    "// The blackbody colours of scene/medium_fire.h: written by tools/gen_blackbody_table.py from\n"
    "// addon/export/node_spectral.py (the Blackbody node's rows: Planck's law against the CIE 1931\n"
    "// observer, linear Rec.709, luminance 1, uniform in 1/T over 800-12000 K). Do not edit.\n"
    "#include \"scene/medium_fire.h\"\n\n"
    "namespace lantern {\n\n"
    "namespace {\n"
    f"constexpr float kTable[3 * kBlackbodyKnots] = {{\n" + "\n".join(lines) + "\n};\n"
    "}  // namespace\n\n"
    "const float* blackbody_table_host() { return kTable; }\n\n"
    "}  // namespace lantern\n")
print(f"wrote {out} ({n} rows)")
