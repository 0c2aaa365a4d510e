"""PTX read as text, for the CUDA resource tools (cuda_kernel_check.py, cuda_kernel_resources.py,
ptx_local_chains.py): each .entry / .func with its body and the functions it calls
(definitions, closure), each entry's local depot (depots), and each function's depot with the
parameter bytes of every call it makes (call_graph). No nvcc or ptxas needed."""

import re

HEAD = re.compile(r"^(?:\.visible |\.weak |\.extern )*\.(entry|func)\s+(?:\([^)]*\)\s*)?([\w$]+)")
CALL = re.compile(r"\bcall(?:\.uni)?\s+(?:\([^)]*\),\s*)?([\w$]+)")
# call_graph's header (as ptx_local_chains.py has read it): the name directly followed by "(";
# HEAD also takes a header whose parameter list starts on the next line
HEAD_OPEN = re.compile(r"^(?:\.visible |\.weak |\.extern )*\.(entry|func)\s+(?:\([^)]*\)\s*)?([\w$]+)\(")
DEPOT = re.compile(r"\.local .*__local_depot\d+\[(\d+)\]")
PARAM = re.compile(r"\.param .*\.b8 \w+\[(\d+)\]")
CALLEE = re.compile(r"call(?:\.uni)?\s*(?:\([^)]*\),\s*)?(_Z[\w$]+)")


def definitions(text):
    """{name: (kind, body lines)} of every .entry and .func defined in a PTX file (a
    declaration, ended by ";" before its "{", is skipped)."""
    out, cur, kind, lines, body = {}, None, None, [], False
    for line in text.splitlines():
        m = HEAD.match(line)
        if m and cur is None:
            kind, cur, lines, body = m.group(1), m.group(2), [line], False
            if line.rstrip().endswith(";"):
                cur = None
            continue
        if cur is None:
            continue
        lines.append(line)
        if not body:
            if line.strip() == "{":
                body = True
            elif line.rstrip().endswith(";"):
                cur = None  # a prototype
            continue
        if line == "}":
            out[cur] = (kind, lines)
            cur = None
    return out


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
