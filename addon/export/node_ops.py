"""The instruction set of node-graph programs as the add-on emits it: opcodes, the modes of
each (Math, Vector Math, Mix, Gradient, Noise, Map Range, the geometry inputs) in the order of
the switch statements in native/src/scene/material_program_*.h, and socket widths. Imports
nothing: node_eval, the handlers and the compilers all read it."""


OP = {name: i for i, name in enumerate((
    "copy", "input", "math", "vector_math", "mix", "map_range", "clamp", "invert", "gamma",
    "bright_contrast", "hsv", "separate", "combine", "rgb_to_bw", "checker", "gradient",
    "noise", "white_noise", "voronoi", "wave", "magic", "ramp", "curves", "fresnel",
    "layer_weight", "image", "mapping", "normalize", "brick", "grid"))}

MATH_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM",
            "SQRT", "INVERSE_SQRT", "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM", "LESS_THAN",
            "GREATER_THAN", "SIGN", "COMPARE", "SMOOTH_MIN", "SMOOTH_MAX", "ROUND", "FLOOR",
            "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO", "WRAP", "SNAP", "PINGPONG",
            "SINE", "COSINE", "TANGENT", "ARCSINE", "ARCCOSINE", "ARCTANGENT", "ARCTAN2", "SINH",
            "COSH", "TANH", "RADIANS", "DEGREES")
VECTOR_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "CROSS_PRODUCT",
              "PROJECT", "REFLECT", "REFRACT", "FACEFORWARD", "DOT_PRODUCT", "DISTANCE",
              "LENGTH", "SCALE", "NORMALIZE", "SNAP", "FLOOR", "CEIL", "MODULO", "WRAP",
              "FRACTION", "ABSOLUTE", "MINIMUM", "MAXIMUM", "SINE", "COSINE", "TANGENT", "POWER",
              "SIGN")
BLEND_MODES = ("MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD",
               "OVERLAY", "SUBTRACT", "DIVIDE", "DIFFERENCE", "EXCLUSION", "SOFT_LIGHT",
               "LINEAR_LIGHT", "HUE", "SATURATION", "VALUE", "COLOR")
GRADIENT_TYPES = ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "RADIAL", "QUADRATIC_SPHERE",
                  "SPHERICAL")
NOISE_TYPES = ("MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "FBM",
               "HETERO_TERRAIN")
MAP_RANGE_MODES = ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")
# kOpInput modes (shade_input)
IN_POSITION, IN_NORMAL, IN_UV, IN_INCOMING, IN_ATTRIBUTE, IN_CAMERA, IN_WINDOW, \
    IN_REFLECTION, IN_TRUE_NORMAL, IN_BACKFACING = range(10)
TABLE_SIZE = 256


def _width(kind):
    return 1 if kind in ("VALUE", "INT", "BOOLEAN") else 3
