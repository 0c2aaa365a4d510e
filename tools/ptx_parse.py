"""PTX read as text, for the CUDA resource tools (cuda_kernel_check.py, cuda_kernel_resources.py,
ptx_local_chains.py): each .entry / .func with its body and the functions it calls
(definitions, closure), one kernel's own PTX module (kernel_ptx) and a digest of its code
(code_digest), each entry's local depot (depots), and each function's depot with the
parameter bytes of every call it makes (call_graph). No nvcc or ptxas needed."""

import hashlib
import re

HEAD = re.compile(r"^(?:\.visible |\.weak |\.extern )*\.(entry|func)\s+(?:\([^)]*\)\s*)?([\w$]+)")
CALL = re.compile(r"\bcall(?:\.uni)?\s+(?:\([^)]*\),\s*)?([\w$]+)")
# call_graph's header (as ptx_local_chains.py has read it): the name directly followed by "(";
# HEAD also takes a header whose parameter list starts on the next line
HEAD_OPEN = re.compile(r"^(?:\.visible |\.weak |\.extern )*\.(entry|func)\s+(?:\([^)]*\)\s*)?([\w$]+)\(")
DEPOT = re.compile(r"\.local .*__local_depot\d+\[(\d+)\]")
PARAM = re.compile(r"\.param .*\.b8 \w+\[(\d+)\]")
CALLEE = re.compile(r"call(?:\.uni)?\s*(?:\([^)]*\),\s*)?(_Z[\w$]+)")


def split_module(text):
    """(module, defs): the module's lines outside every definition, each as (name, line) with
    the name of the prototype it belongs to (else None): header, globals, prototypes, debug
    sections; and {name: (kind, body lines)} of every .entry and .func defined. A body ends
    where its braces balance: inline assembly (CUB's) opens and closes braces of its own, some
    at the start of a line."""
    module, defs, cur, kind, lines, depth = [], {}, None, None, [], 0
    for line in text.splitlines():
        if cur is None:
            m = HEAD.match(line)
            if m and not line.rstrip().endswith(";"):
                kind, cur, lines, depth = m.group(1), m.group(2), [line], 0
                continue
            module.append((m.group(2) if m else None, line))
            continue
        lines.append(line)
        code = line.split("//")[0]
        if depth == 0 and "{" not in code:
            if code.rstrip().endswith(";"):  # a prototype (a declaration without a body)
                module.extend((cur, x) for x in lines)
                cur = None
            continue
        depth += code.count("{") - code.count("}")
        if depth == 0:
            defs[cur] = (kind, lines)
            cur = None
    return module, defs


def definitions(text):
    """{name: (kind, body lines)} of every .entry and .func defined in a PTX file (a
    declaration, ended by ";" before its "{", is skipped)."""
    return split_module(text)[1]


def closure(name, defs):
    """The entry and every function it calls (transitively), in a stable order."""
    seen, todo = [], [name]
    while todo:
        n = todo.pop()
        if n in seen or n not in defs:
            continue
        seen.append(n)
        todo.extend(sorted(set(CALL.findall("\n".join(defs[n][1])))))
    return seen


def kernel_ptx(module, defs, entry):
    """A PTX module of one kernel alone: the module's header, globals and debug sections, the
    prototypes of the functions it calls, and its closure's definitions (in the file's order). ptxas
    reads it in a fraction of the time it takes to read a whole translation unit's PTX (38 MB:
    5 s of CPU and 1 GB for every --entry run) and compiles the same code."""
    parts = closure(entry, defs)
    keep = set(parts)
    out = [line for name, line in module if name is None or name in keep or name not in defs]
    for name, (_, body) in defs.items():  # in the file's order: a callee without a prototype
        if name in keep:                  # is defined before its callers
            out.extend(body)
    return "\n".join(out) + "\n"


# What differs between two compilations of the same kernel code (in another translation unit,
# or another lambda with the same body): the entry's own (mangled) name, the numbering of
# labels, local depots, strings and debug info, comments and source line directives.
_NUMBERED = re.compile(r"(__local_depot|\$L__BB|\$L__info_string|\$L__tmp|\$L__func_begin|"
                       r"\$L__func_end|\$str\$?|__unnamed_)\d+")
# An internal-linkage function's mangled name carries hashes of its translation unit's path and
# build (`_ZN65_INTERNAL_<hex>_28_cuda_schedule_bdpt_camera_cu_<hex>_27243...`, 65 characters):
# the same code compiled in another clone. The whole length-prefixed component is replaced.
_INTERNAL = re.compile(r"(\d+)_INTERNAL_")


def _internal_names(code):
    out, i = [], 0
    for m in _INTERNAL.finditer(code):
        if m.start() < i:
            continue
        n = int(m.group(1))
        out.append(code[i:m.start()] + "INTERNAL#")
        i = m.start(1) + len(m.group(1)) + n
    return "".join(out) + code[i:] if out else code


def code_digest(entry, defs):
    """A digest of what ptxas compiles for this kernel, with its name, numbering, internal names'
    path hashes, comments and .loc lines taken out: kernels with equal digests are the same code (ptxas gives them the
    same registers and stack; tests/python/test_gpu_tools.py checks it on a pair)."""
    h = hashlib.sha256()
    for p in closure(entry, defs):
        for line in defs[p][1]:
            code = line.split("//")[0].rstrip()
            if not code or code.lstrip().startswith(".loc"):
                continue
            code = _internal_names(code.replace(entry, "ENTRY"))
            h.update(_NUMBERED.sub(r"\1#", code).encode() + b"\n")
    return h.hexdigest()[:24]


def depots(ptx_text):
    """Each entry's local depot in the PTX: what cicc already put in local memory (arrays,
    address-taken structures), before ptxas adds its spills. Non-inlined functions have their
    own depots (and frames), not counted here."""
    out, cur = {}, None
    for line in ptx_text.splitlines():
        if line.startswith(".") and (" .entry " in line or line.startswith(".entry ")):
            m = re.search(r"\.entry\s+([\w$]+)", line)
            cur = m.group(1) if m else None
        elif re.match(r"^\.(?:visible |weak |extern )*\.func", line):
            cur = None
        elif cur and ".local" in line and "__local_depot" in line:
            m = re.search(r"__local_depot\d+\[(\d+)\]", line)
            if m:
                out.setdefault(cur, int(m.group(1)))
    return out


def call_graph(lines):
    """{function: {"depot": bytes, "calls": [(callee, param bytes)]}}."""
    funcs, cur, call = {}, None, None
    for line in lines:
        m = HEAD_OPEN.match(line)
        if m:
            cur = m.group(2)
            funcs[cur] = {"depot": 0, "calls": []}
            continue
        if cur is None:
            continue
        m = DEPOT.search(line)
        if m:
            funcs[cur]["depot"] = int(m.group(1))
            continue
        if "{ // callseq" in line:
            call = {"bytes": 0, "callee": None, "next_line": False}
            continue
        if call is None:
            continue
        m = PARAM.search(line)
        if m:
            call["bytes"] += int(m.group(1))
        if re.match(r"\s*call", line):
            m = CALLEE.search(line)
            if m:
                call["callee"] = m.group(1)
            else:
                call["next_line"] = True  # the callee's name is on the next line
            continue
        if call["next_line"]:
            call["callee"], call["next_line"] = line.strip().rstrip(",").strip(), False
        if "} // callseq" in line:
            funcs[cur]["calls"].append((call["callee"], call["bytes"]))
            call = None
    return funcs
