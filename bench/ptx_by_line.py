# instructions of a kernel's closure by source line (innermost .loc), with the line's text
import sys, re, collections, glob, os
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools"))
from ptx_parse import definitions, closure
text = open(sys.argv[1]).read()
files = dict((int(m.group(1)), m.group(2)) for m in re.finditer(r'^\s*\.file\s+(\d+)\s+"([^"]+)"', text, re.M))
defs = definitions(text)
ent = sys.argv[2]
parts = closure(ent, defs) if ent in defs else [n for n in defs if ent in n][:1]
byline = collections.Counter(); byfile = collections.Counter()
for p in parts:
    cur = None
    for l in defs[p][1]:
        s = l.strip()
        if s.startswith(".loc"):
            m = re.match(r"\.loc\s+(\d+)\s+(\d+)", s)
            if m: cur = (files.get(int(m.group(1)), "?"), int(m.group(2)))
            continue
        if s and not s.startswith(("//", ".", "$", "{", "}")) and cur:
            byline[cur] += 1
tot = sum(byline.values())
for (f, ln), c in byline.items(): byfile[f.split("/")[-1]] += c
print("instructions", tot)
for f, c in byfile.most_common(15): print(" ", c, f)
for (f, ln), c in byline.most_common(int(sys.argv[3])):
    try: src = open(f.replace("/work/wt/kernels", "/work/main")).read().splitlines()[ln-1].strip()[:90]
    except Exception: src = "?"
    print(f"{c:7d} {f.split('/')[-1]}:{ln}  {src}")
