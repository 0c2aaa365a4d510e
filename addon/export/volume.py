"""Volume outputs -> homogeneous media (docs/volumes.md): a material's Volume output becomes
the medium inside its mesh ("volume"; a material without a Surface is a pure volume boundary,
"volume_only", which rays pass as in Cycles), the world's Volume the medium filling the scene.
Principled Volume, Volume Scatter (Henyey-Greenstein), Volume Absorption and Emission, under
Add and Mix Shader nodes of constant factors, with constant inputs, convert as Cycles sets up
their closures (kernel/svm/closure.h): scattering Color x Density; Principled absorption
max(1 - Color, 0) x max(1 - sqrt(Absorption Color), 0) x Density; Volume Absorption
max(1 - Color, 0) x Density; emission Strength x Color, and Principled Volume's Blackbody
(blackbody_emission). A node graph on the Density of the one scattering or absorbing shader of
a material's volume makes it heterogeneous: the coefficients above are per unit of density and
the graph becomes the material's "density" program (native/src/scene/medium_hetero.h). Other
graphs (on Color, on the world's volume, on two shaders' densities), other phase functions: a
warning by name, and the socket's own value."""

import math

import numpy as np

from .node_spectral import blackbody_rgb

_SHADERS = ("PRINCIPLED_VOLUME", "VOLUME_SCATTER", "VOLUME_ABSORPTION", "EMISSION")
# inputs that only matter for grids (Volume objects) or other phase functions
_IGNORED = {"Weight", "Color Attribute", "Density Attribute", "Temperature Attribute",
            "IOR", "Backscatter", "Alpha", "Diameter"}


def _source(socket):
    """(node) feeding `socket` through reroutes, or None."""
    for _ in range(16):
        if not socket.is_linked:
            return None
        node = socket.links[0].from_node
        if node.type != "REROUTE":
            return node
        socket = node.inputs[0]
    return None


def _value(node, name, where, report, quiet=False):
    """A constant input: its own value; a linked one is named in a warning (its own value is
    used), unless quiet (a heterogeneous Density: its graph is compiled instead)."""
    sock = node.inputs.get(name)
    if sock is None:
        return None
    if sock.is_linked and _source(sock) is not None and not quiet:
        report.warn(f"{where}: the input '{name}' of '{node.name}' is linked; heterogeneous "
                    "(textured) volumes are not rendered yet, the socket's own value is used")
    v = sock.default_value
    try:
        vals = [float(x) for x in v][:3]
    except TypeError:
        return float(v) if math.isfinite(float(v)) else 0.0
    return [x if math.isfinite(x) else 0.0 for x in vals]


# Cycles' Principled Volume blackbody (kernel/svm/closure.h, measured with bpy 5.0.1): the
# Stefan-Boltzmann law per unit of the Temperature socket, sigma T^4 / pi in W / (m^2 sr) scaled
# by 1e-6, mixed with 1 by the Blackbody Intensity
_SIGMA_BB = 5.670373e-8 * 1e-6 / math.pi
_CUTOFF = 1e-5   # Cycles' CLOSURE_WEIGHT_CUTOFF: smaller intensities add nothing


def blackbody_emission(node, where, report):
    """The emission (RGB, radiance per metre) of a Principled Volume's Blackbody: Blackbody Tint
    x sigma x mix(1, T^4, Blackbody Intensity) x the blackbody colour of T (luminance 1,
    node_spectral.blackbody_rgb, as Cycles' Blackbody node), as Cycles adds it. A mesh has no
    temperature attribute, so T is the Temperature socket's (a Volume object's grid would
    multiply it). Cycles' colour goes negative in blue below about 1900 K; Lantern clamps each
    channel at 0."""
    bb = _value(node, "Blackbody Intensity", where, report)
    if bb is None or not bb > _CUTOFF:
        return [0.0, 0.0, 0.0]
    t = max(_value(node, "Temperature", where, report) or 0.0, 0.0)
    intensity = _SIGMA_BB * ((1.0 - bb) + bb * t ** 4)
    if not intensity > _CUTOFF or not math.isfinite(intensity):
        return [0.0, 0.0, 0.0]
    tint = _value(node, "Blackbody Tint", where, report) or [1.0, 1.0, 1.0]
    color = blackbody_rgb(t)
    return [max(k, 0.0) * intensity * max(c, 0.0) for k, c in zip(tint, color)]


def _leaves(socket, weight, where, report, depth=0):
    """[(shader node, weight)] below a Volume socket through Add and Mix Shader nodes."""
    node = _source(socket)
    if node is None or weight <= 0.0:
        return []
    if depth > 16:
        report.warn(f"{where}: volume shader mixes nested too deep; cut")
        return []
    if node.type == "ADD_SHADER":
        return (_leaves(node.inputs[0], weight, where, report, depth + 1) +
                _leaves(node.inputs[1], weight, where, report, depth + 1))
    if node.type == "MIX_SHADER":
        f = _value(node, "Fac", where, report)
        f = min(max(float(f), 0.0), 1.0)
        return (_leaves(node.inputs[1], weight * (1.0 - f), where, report, depth + 1) +
                _leaves(node.inputs[2], weight * f, where, report, depth + 1))
    return [(node, weight)]


def _hetero_leaf(leaves, where, report, compiler):
    """The one scattering or absorbing leaf whose Density a node graph drives, compiled into a
    "density" program: (node, program), or (None, None) when there is none or it cannot be
    rendered (then a warning names it and the socket's own value is used)."""
    if compiler is None:
        return None, None
    media = [n for n, _ in leaves if n.type in _SHADERS and n.type != "EMISSION"]
    driven = [n for n in media if n.inputs.get("Density") is not None and
              n.inputs["Density"].is_linked and _source(n.inputs["Density"]) is not None]
    if not driven:
        return None, None
    if len(media) > 1:
        report.warn(f"{where}: a node graph on Density with other volume shaders beside it is "
                    "not rendered (one shader's density only); the socket's own value is used")
        return None, None
    prog = compiler.program(driven[0].inputs["Density"], "density", 1)
    return (driven[0], prog) if prog is not None else (None, None)


def _linked(node, name):
    sock = node.inputs.get(name)
    return sock is not None and sock.is_linked and _source(sock) is not None


def _check_color(report, where, node, name, prog):
    """Warn where a colour program gives negative values at a probe point (negative_emission's
    probe: the unit cube's points, where mesh volumes' Generated coordinates lie): Lantern takes
    them as 0 (medium_color_at), where Cycles uses them as they are (a negative colour scatters
    or emits negatively). Non-finite values are 0 in both the probe and the render
    (program_run); a Volume object's grids read 0 in the probe (nothing to say there)."""
    from .negative_emission import _NORMALS, _POINTS, _probe_program
    from .node_light import evaluate
    try:
        vals = evaluate(_probe_program(prog), _POINTS, _NORMALS)
    except (ValueError, RuntimeError, TypeError):
        return
    if vals is None:
        return
    neg = vals < -max(0.05 * float(np.abs(vals).max()), 1e-4)
    if neg.any():
        frac = float(neg.any(axis=1).mean())
        report.warn(f"{where}: the node graph on '{name}' of '{node.name}' gives negative "
                    f"values (at {100.0 * frac:.0f} % of probe points, down to "
                    f"{float(vals.min()):.4g}); Lantern takes them as 0 there, Cycles uses them "
                    "as they are (negative scattering or light)")


def _color_leaves(leaves, where, report, compiler, gridded):
    """(node, "volume_color" program) of the one scattering or absorbing leaf whose Color a
    node graph drives, (node, "volume_absorption_color" program) of the one Principled Volume
    whose Absorption Color a graph drives and (node, "volume_emission_color" program) of the one
    leaf whose Emission Color (Principled Volume) or Color (Emission) a graph drives; (None,
    None) each where there is none or it cannot be rendered (a warning names it; the socket's
    value). The Color's and the Absorption Color's graphs may be two shaders' (the Absorption
    Color's shader's absorption is then "absorb_alone": convert_volume)."""
    out = []
    for target, kinds, name_of in (
            ("volume_color", ("PRINCIPLED_VOLUME", "VOLUME_SCATTER", "VOLUME_ABSORPTION"),
             lambda n: "Color"),
            ("volume_absorption_color", ("PRINCIPLED_VOLUME",), lambda n: "Absorption Color"),
            ("volume_emission_color", ("PRINCIPLED_VOLUME", "EMISSION"),
             lambda n: "Emission Color" if n.type == "PRINCIPLED_VOLUME" else "Color")):
        found = None, None
        if compiler is not None:
            for node, w in leaves:
                name = name_of(node) if node.type in kinds else None
                if name is None or not _linked(node, name) or (node, name) in gridded:
                    continue
                if found[0] is not None:
                    report.warn(f"{where}: a second node graph on '{name}' of '{node.name}' is "
                                "not rendered (one per volume); the socket's own value is used")
                    continue
                prog = compiler.program(node.inputs[name], target, 3)
                if prog is not None:
                    found = node, prog
                    _check_color(report, where, node, name, prog)
        out.append(found)
    return out


def _strength_leaf(leaves, where, report, compiler, gridded, enode):
    """(node, "volume_emission" program) of the one leaf whose Emission Strength (Principled
    Volume) or Strength (Emission) a node graph drives in a mesh volume (a Volume object's are
    in `gridded`: volume_objects._GridProbe), or (None, None). The core emits flame_emission x
    max(its value, 0) per point (scene/medium_fire.h), times the Emission Color graph's colour
    where that is the same shader's; a strength graph beside another shader's Emission Color
    graph, or a second one, warns by name (the socket's value)."""
    found = None, None
    if compiler is None:
        return found
    for node, w in leaves:
        name = {"PRINCIPLED_VOLUME": "Emission Strength", "EMISSION": "Strength"}.get(node.type)
        if name is None or not _linked(node, name) or (node, name) in gridded:
            continue
        if found[0] is not None or (enode is not None and enode is not node):
            report.warn(f"{where}: the node graph on '{name}' of '{node.name}' is not rendered "
                        "beside another shader's emission graph (one emission graph per volume); "
                        "the socket's own value is used")
            continue
        prog = compiler.program(node.inputs[name], "volume_emission", 1)
        if prog is not None:
            found = node, prog
            _check_color(report, where, node, name, prog)
    return found


def convert_volume(socket, where, report, compiler=None, programs=None):
    """The medium dict of the shaders under a Volume socket, or None (nothing renders). With a
    GraphCompiler, a graph on the Density of the volume's one shader appends its "density"
    program to `programs` (the material's) and the coefficients are per unit of density."""
    sigma_a, sigma_s, emission = [0.0] * 3, [0.0] * 3, [0.0] * 3
    lobes = []  # (scattering luminance, g)
    leaves = _leaves(socket, 1.0, where, report)
    hetero, prog = _hetero_leaf(leaves, where, report, compiler)
    if prog is not None and programs is not None:
        programs.append(prog)
    # a Volume object's grid on an emission strength or colour (volume_objects._GridProbe):
    # the probe keeps it (a flame or colour grid) and the constant strength is 0
    by_grid = getattr(compiler, "grid_strength", None)
    gridded = {(node, sock.name) for node, w in leaves if node.type in _SHADERS
               for sock in node.inputs if by_grid is not None and by_grid(node, sock, w)}
    (cnode, cprog), (anode, aprog), (enode, eprog) = _color_leaves(leaves, where, report,
                                                                   compiler, gridded)
    snode, sprog = _strength_leaf(leaves, where, report, compiler, gridded, enode)
    color_scatter, color_absorb, flame = [0.0] * 3, [0.0] * 3, [0.0] * 3
    absorb_alone = [0.0] * 3   # an Absorption Color graph's shader beside another's Color graph
    color_base = [1.0] * 3   # the colour where no program gives it (an Absorption Color's)
    for prog in (cprog, aprog, eprog, sprog):
        if prog is not None and programs is not None:
            programs.append(prog)
    for node, w in leaves:
        if node.type not in _SHADERS:
            report.warn(f"{where}: '{node.name}' ({node.type}) in the Volume output is not "
                        "rendered")
            continue
        by_prog = set()   # the inputs a colour program drives
        if node is cnode:
            by_prog.add("Color")
        if node is anode:
            by_prog.add("Absorption Color")
        if node is enode:
            by_prog.add("Emission Color" if node.type == "PRINCIPLED_VOLUME" else "Color")
        if node is snode:
            by_prog.add("Emission Strength" if node.type == "PRINCIPLED_VOLUME" else "Strength")
        own = {name for n, name in gridded if n is node} | by_prog
        for sock in node.inputs:
            if sock.name not in _IGNORED and sock.is_linked and _source(sock) is not None and \
                    not (node is hetero and sock.name == "Density") and sock.name not in own:
                _value(node, sock.name, where, report)  # names it
        color = _value(node, "Color", where, report, quiet="Color" in own) or [1.0, 1.0, 1.0]
        if node.type == "EMISSION":
            s = 0.0 if "Strength" in own else _value(node, "Strength", where, report)
            if node is enode:   # the program's colour per point x the weight x the strength
                # (a Volume object's strength graph or flame grid: the probe's factor, _fire)
                flame = [f + w * (1.0 if "Strength" in own else s) for f in flame]
                continue
            if node is snode:   # a mesh volume's strength graph x the weight x the colour
                flame = [f + w * max(c, 0.0) for f, c in zip(flame, color)]
                continue
            emission = [e + w * s * c for e, c in zip(emission, color)]
            continue
        density = w * (1.0 if node is hetero else
                       max(_value(node, "Density", where, report, quiet=True), 0.0))
        if node is cnode:
            # the colour program's c per point (the core: scattering color_scatter x c,
            # absorption color_absorb x max(1 - c, 0), as Cycles sets up the closures)
            color = [0.0, 0.0, 0.0]   # nothing of the socket's colour in sigma_a, sigma_s
            if node.type != "VOLUME_ABSORPTION":
                color_scatter = [x + density for x in color_scatter]
            if node.type == "VOLUME_ABSORPTION":
                color_absorb = [x + density for x in color_absorb]
        if node.type == "VOLUME_ABSORPTION":
            sigma_a = [a + density * max(1.0 - c, 0.0) * (0.0 if node is cnode else 1.0)
                       for a, c in zip(sigma_a, color)]
            continue
        g = _value(node, "Anisotropy", where, report)
        g = 0.0 if g is None else g  # a phase function without one (Volume Scatter's Rayleigh)
        scatter = [density * max(c, 0.0) for c in color]
        sigma_s = [a + b for a, b in zip(sigma_s, scatter)]
        lobes.append((density if node is cnode else
                      0.2126 * scatter[0] + 0.7152 * scatter[1] + 0.0722 * scatter[2], g))
        if node.type == "VOLUME_SCATTER":
            phase = getattr(node, "phase", "HENYEY_GREENSTEIN")
            if phase != "HENYEY_GREENSTEIN":
                report.warn(f"{where}: the phase function '{phase}' of '{node.name}' is not "
                            "rendered; Henyey-Greenstein of its Anisotropy stands for it")
            continue
        absorb = _value(node, "Absorption Color", where, report, quiet=node is anode)
        kabs = [max(1.0 - math.sqrt(max(k, 0.0)), 0.0) for k in absorb]
        if node is anode:   # the program's max(1 - sqrt(a), 0) per point stands for kabs
            kabs = [1.0, 1.0, 1.0]
            if cnode is not None and node is not cnode:
                # the Color graph is another shader's: this one's absorption max(1 - Color, 0)
                # x Density is the absorption factor's alone (the core: absorb_alone)
                absorb_alone = [x + density * max(1.0 - c, 0.0)
                                for x, c in zip(absorb_alone, color)]
            elif node is not cnode:   # the constant Color, as the colour of its absorption
                color_base = [max(c, 0.0) for c in color]
        if node is anode and cnode is not None and node is not cnode:
            pass
        elif node is cnode or node is anode:
            color_absorb = [x + density * k for x, k in zip(color_absorb, kabs)]
        else:
            sigma_a = [a + density * max(1.0 - c, 0.0) * k
                       for a, c, k in zip(sigma_a, color, kabs)]
        strength = 0.0 if "Emission Strength" in own else \
            _value(node, "Emission Strength", where, report)
        if node is enode:
            # a Volume object's strength graph or flame grid keeps its own factor (the probe's)
            s = w if "Emission Strength" in own else w * strength
            flame = [f + s for f in flame]
        else:
            ecolor = _value(node, "Emission Color", where, report, quiet="Emission Color" in own)
            if node is snode:   # a mesh volume's strength graph x the weight x the colour
                flame = [f + w * max(c, 0.0) for f, c in zip(flame, ecolor)]
            else:
                emission = [e + w * strength * c for e, c in zip(emission, ecolor)]
        bb = blackbody_emission(node, where, report)
        emission = [e + w * b for e, b in zip(emission, bb)]
    total = sum(s for s, _ in lobes)
    g = sum(s * gg for s, gg in lobes) / total if total > 0.0 else 0.0
    if len({round(gg, 6) for s, gg in lobes if s > 0.0}) > 1:
        report.warn(f"{where}: volume scatterers of different Anisotropy are mixed; one lobe of "
                    f"their mean anisotropy {g:.3g} stands for them")
    out = {"sigma_a": sigma_a, "sigma_s": sigma_s, "emission": emission,
           "g": min(max(g, -0.999), 0.999)}
    if aprog is not None and cnode is not None and anode is not cnode and \
            not max(absorb_alone) > 0.0:
        # the Absorption Color's shader absorbs nothing (its Color white): its graph changes
        # nothing (kept, the core would take it for the Color's shader's factor)
        if programs is not None:
            programs.remove(aprog)
        aprog = None
    if (cprog is not None or aprog is not None) and \
            max(color_scatter + color_absorb + absorb_alone) > 0.0:
        out["color_scatter"], out["color_absorb"] = color_scatter, color_absorb
        out["color_base"] = color_base
        if max(absorb_alone) > 0.0:
            out["absorb_alone"] = absorb_alone
    elif programs is not None:   # the colour changes nothing (a density of 0)
        for prog in (cprog, aprog):
            if prog is not None:
                programs.remove(prog)
    if (eprog is not None or sprog is not None) and max(flame) > 0.0:
        out["flame_emission"] = flame
    elif programs is not None:
        for prog in (eprog, sprog):
            if prog is not None:
                programs.remove(prog)
    if max(sigma_a + sigma_s + emission + out.get("color_scatter", [0.0]) +
           out.get("color_absorb", [0.0]) + out.get("flame_emission", [0.0])) <= 0.0:
        return None
    return out


def _output(tree, kind):
    outs = [n for n in tree.nodes if n.type == kind]
    return next((n for n in outs if getattr(n, "is_active_output", False)), None) or \
        (outs[0] if outs else None)


def attach_material_volume(material, out, report, compiler=None):
    """out (a converted material dict) with the material's Volume output: "volume" and, without
    a Surface, "volume_only"; a graph on Density (with a GraphCompiler, material_compile): its
    "density" program in out["programs"]. Returns out."""
    tree = getattr(material, "node_tree", None)
    output = _output(tree, "OUTPUT_MATERIAL") if tree is not None else None
    if output is None or output.inputs.get("Volume") is None or \
            _source(output.inputs["Volume"]) is None:
        return out
    where = f"Material '{material.name}'"
    programs = []
    medium = convert_volume(output.inputs["Volume"], where, report, compiler, programs)
    if medium is not None:
        out["volume"] = medium
        if programs:
            out.setdefault("programs", []).extend(programs)
    if _source(output.inputs["Surface"]) is None:
        if medium is None:
            # no surface and nothing inside (a Volume of Density 0: fog switched off): Cycles'
            # rays and shadow rays pass the mesh and meet nothing, as if it were not there;
            # Lantern passes it as a fully transparent surface (alpha 0), which needs no medium
            # (a volume boundary is crossed only where the scene has media)
            out["alpha"] = 0.0
            out.pop("alpha_texture", None)
        else:
            out["volume_only"] = True  # no surface: rays pass its boundary (Cycles)
    return out


def attach_world_volume(world, out, report):
    """out (the world dict) with the world's Volume output as "volume". Returns out."""
    tree = getattr(world, "node_tree", None) if world is not None else None
    output = _output(tree, "OUTPUT_WORLD") if tree is not None else None
    if output is None or output.inputs.get("Volume") is None:
        return out
    medium = convert_volume(output.inputs["Volume"], f"World '{world.name}'", report)
    if medium is not None:
        out["volume"] = medium
    return out


def volume_settings(scene, report):
    """Render settings of volumes that Lantern does not honour, named once per export."""
    c = getattr(scene, "cycles", None)
    if c is None:
        return
    # Volume Step (Step Rate, Max Steps, a Volume's Step Size) steers only Cycles' biased ray
    # marching; its default (null scattering) and Lantern's tracking are unbiased and take no
    # steps, so they are not honoured: named only when Cycles would march (docs/volumes.md)
    if getattr(c, "volume_biased", False):
        report.warn(f"Render settings: Cycles' biased volume ray marching (Step Rate "
                    f"{getattr(c, 'volume_step_rate', 1.0):g}, Max Steps "
                    f"{getattr(c, 'volume_max_steps', 0)}) is not what Lantern renders; its "
                    "volume tracking is unbiased (Cycles' default, null scattering) and takes no "
                    "steps")
    vb, mb = getattr(c, "volume_bounces", None), getattr(c, "max_bounces", None)
    if vb is not None and mb is not None and vb < mb:
        report.warn(f"Render settings: Volume Bounces ({vb}) is not honoured; Lantern scatters "
                    f"in volumes up to Max Bounces (Cycles stops after {vb} volume scatterings)")
