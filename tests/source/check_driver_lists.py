#!/usr/bin/env python3
"""The backends' one naming scheme (docs/ARCHITECTURE.md, core/exec/dispatch.h): every backend
driver is an entry of its stage's WB_*_KERNELS list, defined once; no dispatcher is written by
hand; no backend declaration is written outside a list. Exits 1 with what is wrong."""
import pathlib
import re
import sys

core = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "src/core")
problems = []

# The lists: X(return, name, (parameters), (arguments)) entries of #define WB_*_KERNELS(X).
listed = {}
for h in sorted(core.rglob("*.h")):
    text = h.read_text()
    for m in re.finditer(r"#define (WB_\w+_KERNELS)\(X\)((?:[^\n]*\\\n)*[^\n]*)", text):
        for e in re.finditer(r"\bX\(\s*[\w:]+\s*,\s*(\w+)\s*,", m.group(2)):
            listed.setdefault(e.group(1), []).append(f"{h.name}:{m.group(1)}")
if not listed:
    problems.append(f"no WB_*_KERNELS list under {core}")


def top_level_functions(text):
    """Functions defined at the top level of a backend namespace (not in detail or anonymous)."""
    names, depth, hidden, previous = [], 0, [], ""
    for line in text.splitlines():
        stripped = line.strip()
        if re.match(r"namespace (detail|)\s*\{", stripped):
            hidden.append(depth)
        m = re.match(r"^(?:inline |static )?[\w:<>]+\*? (\w+)\(", line)
        if m and depth == 1 and not hidden and not line.rstrip().endswith(";") and \
                not previous.startswith("template"):  # a launch helper, not a driver
            names.append(m.group(1))
        previous = stripped
        depth += line.count("{") - line.count("}")
        while hidden and depth <= hidden[-1]:
            hidden.pop()
    return names


defined = {}
for src in sorted(list(core.rglob("*_impl.h")) + list(core.rglob("algorithms_cpu.cpp")) +
                  list(core.rglob("algorithms_cuda.cu"))):
    text = src.read_text()
    if "namespace wb::WB_BACKEND_NS" not in text and "namespace wb::cpu" not in text and \
            "namespace wb::cuda" not in text:
        continue
    for name in top_level_functions(text):
        defined.setdefault(name, []).append(src.name)
        if name not in listed:
            problems.append(f"{src}: backend driver {name} is in no WB_*_KERNELS list")
for name, where in listed.items():
    if name not in defined:
        problems.append(f"{where[0]}: {name} is listed but defined in no backend source")

# The switch and the backend namespaces are written in one place.
for f in sorted(list(core.rglob("*.cpp")) + list(core.rglob("*.h")) + list(core.rglob("*.cu"))):
    if f.name == "dispatch.h":
        continue
    text = f.read_text()
    if re.search(r"WB_DISPATCH\(", text) and f.name != "algorithms.cpp":
        problems.append(f"{f}: a dispatcher written by hand (WB_DISPATCH outside a list's dispatchers)")
    if re.search(r"^namespace (cpu|cuda) \{", text, re.M):
        problems.append(f"{f}: backend declarations written by hand (namespace cpu/cuda block)")

print(f"{len(listed)} drivers listed, {len(defined)} defined")
for p in problems:
    print(p)
sys.exit(1 if problems else 0)
