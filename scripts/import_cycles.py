#!/usr/bin/env python3
"""Import circles between sibling modules of each folder of src/ (issue 27 §2).

For every folder, the modules are its files and subfolders (`foo.rs` + `foo/` count as one
module `foo`). A module uses a sibling when any of its files names it through
`super::NAME` (from a file directly in the folder) or `crate::<folder path>::NAME`.
Comment lines, test files (`tests.rs`, `testing.rs`) and what follows a top-level
`#[cfg(test)]` (the unit tests at the end of a file) are ignored.
Prints every cycle of that graph; exits 1 if there is one.
"""
import os, re, sys

root = sys.argv[1] if len(sys.argv) > 1 else "src"
found = 0
for folder, dirs, files in os.walk(root):
    mods = {f[:-3] for f in files if f.endswith(".rs") and f not in ("mod.rs", "lib.rs", "main.rs")}
    mods |= set(dirs)
    if len(mods) < 2:
        continue
    crate_path = "crate::" + "::".join(os.path.relpath(folder, root).split(os.sep)) if folder != root else "crate"
    graph = {m: set() for m in mods}
    for m in mods:
        paths = []
        if os.path.isfile(os.path.join(folder, m + ".rs")):
            paths.append((os.path.join(folder, m + ".rs"), 1))
        sub = os.path.join(folder, m)
        if os.path.isdir(sub):
            for d, _, fs in os.walk(sub):
                depth = os.path.relpath(d, folder).count(os.sep) + 2
                paths += [(os.path.join(d, f), depth) for f in fs if f.endswith(".rs")]
        for p, depth in paths:
            if os.path.basename(p) in ("tests.rs", "testing.rs"):
                continue
            if os.path.basename(p) == "mod.rs":
                depth -= 1
            up = "::".join(["super"] * depth)
            for line in open(p, encoding="utf-8"):
                if line.startswith("#[cfg(test)]"):
                    break  # the unit tests at the end of a file may use anything
                s = line.strip()
                if s.startswith("//"):
                    continue
                for pre in (up, crate_path):
                    for n in re.findall(re.escape(pre) + r"::(\w+)", s):
                        if n in mods and n != m:
                            graph[m].add(n)
                    # `use super::{a, b::c}` groups
                    for grp in re.findall(re.escape(pre) + r"::\{([^}]*)\}", s):
                        for n in re.findall(r"(?:^|,)\s*(\w+)", grp):
                            if n in mods and n != m:
                                graph[m].add(n)
    # cycles by DFS
    state, stack = {}, []
    def dfs(u):
        global found
        state[u] = 1; stack.append(u)
        for v in sorted(graph[u]):
            if state.get(v) == 1:
                print(f"{folder}: " + " -> ".join(stack[stack.index(v):] + [v])); found += 1
            elif v not in state:
                dfs(v)
        stack.pop(); state[u] = 2
    for m in sorted(mods):
        if m not in state:
            dfs(m)
print(f"{found} import cycle(s)")
sys.exit(1 if found else 0)
