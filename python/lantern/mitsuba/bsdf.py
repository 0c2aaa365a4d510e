"""Mitsuba BSDFs to Lantern materials: diffuse, (rough)conductor with complex Fresnel,
(rough)dielectric; plastics and principled fall back to a diffuse (docs/mitsuba_import.md).

`_BsdfReader` is mixed into the loader; it needs `props`, `_child_objects` and `warn`."""

import math

from .common import FALLBACK_BSDFS, WRAPPER_BSDFS, MitsubaError

# Mitsuba 3's named indices of refraction (src/core/ior.h), for int_ior / ext_ior.
DIELECTRIC_IOR = {
    "vacuum": 1.0, "helium": 1.00004, "hydrogen": 1.00013, "air": 1.000277,
    "carbon dioxide": 1.00045, "water": 1.3330, "acetone": 1.36, "ethanol": 1.361,
    "carbon tetrachloride": 1.461, "glycerol": 1.4729, "benzene": 1.501,
    "silicone oil": 1.52045, "bromine": 1.661, "water ice": 1.31, "fused quartz": 1.458,
    "pyrex": 1.470, "acrylic glass": 1.49, "polypropylene": 1.49, "bk7": 1.5046,
    "sodium chloride": 1.544, "amber": 1.55, "pet": 1.5750, "diamond": 2.419,
}

# Conductor `material` presets: RGB eta, k of Tungsten's ComplexIorData.hpp (Bitterli's
# spectral data integrated to linear sRGB; veach-mis's explicit eta/k are its "Cu").
# Mitsuba integrates the spectra itself, so its RGB differs slightly. "none" is Mitsuba's
# default: eta 0, k 1, a perfect mirror (times specular_reflectance).
CONDUCTOR_PRESETS = {
    "none": ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)),
    "a-C": ((2.9440999183, 2.2271502925, 1.9681668794), (0.8874329109, 0.7993216383, 0.8152862927)),
    "Ag": ((0.1552646489, 0.1167232965, 0.1383806959), (4.8283433224, 3.1222459278, 2.1469504455)),
    "Al": ((1.6574599595, 0.8803689579, 0.5212287346), (9.2238691996, 6.2695232477, 4.8370012281)),
    "Au": ((0.1431189557, 0.3749570432, 1.4424785571), (3.9831604247, 2.3857207478, 1.6032152899)),
    "Be": ((4.1850592788, 3.1850604423, 2.7840913457), (3.8354398268, 3.0101260162, 2.8690088743)),
    "Cr": ((4.3696828663, 2.9167024892, 1.6547005413), (5.2064337956, 4.2313645277, 3.7549467933)),
    "Cu": ((0.2004376970, 0.9240334304, 1.1022119527), (3.9129485033, 2.4528477015, 2.1421879552)),
    "Cu2O": ((3.5492833755, 2.9520622449, 2.7369202137),
            (0.1132179294, 0.1946659670, 0.6001681264)),
    "CuO": ((3.2453822204, 2.4496293965, 2.1974114493), (0.5202739621, 0.5707372756, 0.7172250613)),
    "Hg": ((2.3989314904, 1.4400254917, 0.9095512090), (6.3276269444, 4.3719414152, 3.4217899270)),
    "Ir": ((3.0864098394, 2.0821938440, 1.6178866805), (5.5921510077, 4.0671757150, 3.2672611269)),
    "K": ((0.0640493070, 0.0464100621, 0.0381842017), (2.1042155920, 1.3489364357, 0.9132113889)),
    "Li": ((0.2657871942, 0.1956102432, 0.2209198538), (3.5401743407, 2.3111306542, 1.6685930000)),
    "Mo": ((4.4837010280, 3.5254578255, 2.7760769438), (4.1111307988, 3.4208716252, 3.1506031404)),
    "Na": ((0.0602665320, 0.0561412435, 0.0619909494), (3.1792906496, 2.1124800781, 1.5790940266)),
    "Nb": ((3.4201353595, 2.7901921379, 2.3955856658), (3.4413817900, 2.7376437930, 2.5799132708)),
    "Ni": ((2.3672753521, 1.6633583302, 1.4670554172), (4.4988329911, 3.0501643957, 2.3454274399)),
    "Rh": ((2.5857954933, 1.8601866068, 1.5544279524), (6.7822927110, 4.7029501026, 3.9760892461)),
    "Ta": ((2.0625846607, 2.3930915569, 2.6280684948), (2.4080467973, 1.7413705864, 1.9470377016)),
    "TiN": ((1.6484691607, 1.1504482522, 1.3797795097), (3.3684596226, 1.9434888540, 1.1020123347)),
    "V": ((4.2775126218, 3.5131538236, 2.7611257461), (3.4911844504, 2.8893580874, 3.1116965117)),
    "W": ((4.3707029924, 3.3002972445, 2.9982666528), (3.5006778591, 2.6048652781, 2.2731930614)),
}
CONDUCTOR_PRESETS["Na_palik"] = CONDUCTOR_PRESETS["Na"]
CONDUCTOR_PRESETS["Ni_palik"] = CONDUCTOR_PRESETS["Ni"]


def roughness_from_alpha(alpha):
    """Blender roughness (Lantern's) of a Mitsuba alpha: alpha = roughness^2."""
    return math.sqrt(min(max(float(alpha), 0.0), 1.0))


class _BsdfReader:
    """BSDF elements to `Scene.add_material` keyword arguments."""

    def bsdf_material(self, el, name=None):
        """{type, base_color, roughness, ior, eta, k} (only what applies) of a BSDF element;
        `name` (its id, or an enclosing wrapper's) names it in warnings."""
        btype = el.get("type")
        name = el.get("id") or name or btype
        p = self.props(el)
        if btype in WRAPPER_BSDFS:
            inner = self._child_objects(el, "bsdf")
            if not inner:
                raise MitsubaError(f"bsdf {btype!r} without a nested bsdf")
            if btype != "twosided":
                self.warn(f"bsdf {btype!r}: ignored, using its nested bsdf")
            return self.bsdf_material(inner[0], name)
        if btype == "diffuse":
            return {"type": "diffuse", "base_color": self.reflectance(el, p, "reflectance", 0.5)}
        if btype in ("conductor", "roughconductor"):
            return self.conductor(el, p, btype == "roughconductor", name)
        if btype in ("dielectric", "roughdielectric"):
            return self.dielectric(el, p, btype == "roughdielectric", name)
        if btype in FALLBACK_BSDFS:
            self.fallback_types[btype] = self.fallback_types.get(btype, 0) + 1
            if btype in ("plastic", "roughplastic", "pplastic"):
                color = self.reflectance(el, p, "diffuse_reflectance", 0.5)
            elif btype in ("principled", "principledthin"):
                color = self.reflectance(el, p, "base_color", 0.5)
            else:
                color = [0.8, 0.8, 0.8]
            return {"type": "diffuse", "base_color": color}
        self.warn(f"bsdf {btype!r} is not supported; using a grey diffuse (0.5)")
        return {"type": "diffuse", "base_color": [0.5, 0.5, 0.5]}

    # ---- microfacet roughness ----

    def roughness(self, el, p, rough, name, default_alpha=0.1, beckmann_ok=False):
        """Lantern roughness of a (rough) BSDF: sqrt(alpha). Conductors keep Beckmann
        (beckmann_ok); elsewhere it is read as GGX (one warning)."""
        if not rough:
            return 0.0
        dist = p.get("distribution", "beckmann")   # Mitsuba 3's default
        if dist == "beckmann" and not beckmann_ok:
            self.beckmann.setdefault(name, None)
        elif dist not in ("ggx", "beckmann"):
            self.warn(f"microfacet distribution {dist!r}: read as GGX")
        if any(c.tag == "texture" and c.get("name", "").startswith("alpha") for c in el):
            self.warn(f"textured alpha ({el.get('type')}): not supported; using the default "
                      f"or the scalar given")
        if "alpha_u" in p or "alpha_v" in p:
            au, av = (self.scalar(p, n, default_alpha) for n in ("alpha_u", "alpha_v"))
            if not math.isclose(au, av, rel_tol=1e-6):
                self.warn(f"anisotropic alpha_u {au}, alpha_v {av}: Lantern's microfacets are "
                          f"isotropic; using alpha = sqrt(alpha_u alpha_v)")
            alpha = math.sqrt(au * av)
        else:
            alpha = self.scalar(p, "alpha", default_alpha)
        if alpha > 1.0:
            self.warn(f"alpha {alpha} > 1: clamped to 1")
        return roughness_from_alpha(alpha)

    def scalar(self, p, name, default):
        v = p.get(name, default)
        if isinstance(v, list):
            v = sum(v) / len(v)
        if isinstance(v, str):
            raise MitsubaError(f"{name}={v!r}: expected a number")
        return float(v)

    # ---- conductors ----

    def conductor(self, el, p, rough, name):
        """Mitsuba's conductor: Fresnel of eta + i k (explicit, or the `material` preset;
        explicit eta wins, defaults eta 0, k 1 as in Mitsuba), times specular_reflectance."""
        material = p.get("material", "none")
        if "eta" in p or material == "none":
            eta = self.rgb_or_scalar(p, "eta", 0.0)
            k = self.rgb_or_scalar(p, "k", 1.0)
        elif material in CONDUCTOR_PRESETS:
            eta, k = (list(v) for v in CONDUCTOR_PRESETS[material])
        else:
            self.warn(f"conductor material {material!r} is not in the preset table; using a "
                      f"perfect mirror (eta 0, k 1)")
            eta, k = [0.0] * 3, [1.0] * 3
        # Mitsuba's distribution as it is (Beckmann is its default), and no multiple-scattering
        # compensation: Mitsuba and Tungsten have none
        dist = p.get("distribution", "beckmann") if rough else "ggx"
        return {"type": "conductor",
                "base_color": self.reflectance(el, p, "specular_reflectance", 1.0),
                "roughness": self.roughness(el, p, rough, name, beckmann_ok=True),
                "distribution": "beckmann" if dist == "beckmann" else "ggx",
                "multiscatter": False,
                "eta": [max(float(x), 0.0) for x in eta], "k": [max(float(x), 0.0) for x in k]}

    def rgb_or_scalar(self, p, name, default):
        v = p.get(name, default)
        if isinstance(v, str):
            raise MitsubaError(f"{name}={v!r}: expected a number or a colour")
        return [float(x) for x in v] if isinstance(v, list) else [float(v)] * 3

    # ---- dielectrics ----

    def ior(self, p, name, default):
        v = p.get(name, default)
        if isinstance(v, str):
            key = v.strip().lower()
            if key not in DIELECTRIC_IOR:
                try:
                    return float(key)
                except ValueError:
                    raise MitsubaError(f"{name}={v!r}: unknown index of refraction "
                                       f"(known: {', '.join(sorted(DIELECTRIC_IOR))})") from None
            return DIELECTRIC_IOR[key]
        if isinstance(v, list):
            raise MitsubaError(f"{name}: expected a number or a name, got a colour")
        return float(v)

    def dielectric(self, el, p, rough, name):
        """ior = int_ior / ext_ior; specular_transmittance tints transmission."""
        ior = self.ior(p, "int_ior", "bk7") / self.ior(p, "ext_ior", "air")
        if not 0.01 <= ior <= 100.0:
            raise MitsubaError(f"dielectric ior {ior}: outside [0.01, 100]")
        refl = self.reflectance(el, p, "specular_reflectance", 1.0)
        if min(refl) < 1.0:
            self.warn(f"dielectric specular_reflectance {refl}: not supported (Lantern's "
                      f"reflection is untinted); ignored")
        return {"type": "dielectric", "ior": ior,
                "base_color": self.reflectance(el, p, "specular_transmittance", 1.0),
                "roughness": self.roughness(el, p, rough, name)}

    # ---- colours ----

    def reflectance(self, el, p, name, default):
        if name in p and isinstance(p[name], list):
            c = [float(x) for x in p[name]]
        elif name in p:
            c = [float(p[name])] * 3
        else:
            tex = [t for t in self._child_objects(el, "texture") if t.get("name") == name]
            tex += [c for c in el if c.tag == "texture" and c.get("name") == name]
            if tex:
                tp = self.props(tex[0])
                if tex[0].get("type") == "checkerboard":
                    c0 = tp.get("color0", [0.4] * 3)
                    c1 = tp.get("color1", [0.2] * 3)
                    c = [(a + b) / 2 for a, b in zip(c0, c1)]
                else:
                    c = [0.5, 0.5, 0.5]
                self.warn(f"texture {tex[0].get('type')!r} for {name!r}: textures are not "
                          f"supported; using its mean colour {c}")
            else:
                c = [default] * 3
        if max(c) > 1.0 or min(c) < 0.0:
            self.warn(f"reflectance {c} outside [0, 1]: clamped")
            c = [min(max(x, 0.0), 1.0) for x in c]
        return c
