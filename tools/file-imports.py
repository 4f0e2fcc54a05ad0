#!/usr/bin/env python3
"""The imports between the files of one module, and any circle among them.

    python3 tools/file-imports.py src/contact

For every `.rs` file under the folder, the files of the same module it names in code (comment
lines left out): `super::…`, `crate::MODULE::…`, `self::…` and its child modules' paths
(`use child::…`, `child::item`); an inline `mod tests {` counts as part of its file. Prints one
line per file, `file -> files it imports`, then the circles found (`none` when the graph goes one
way), and exits 1 when there is one. A parent's `mod child;` is containment, not an import; a
child that adds methods to its parent's type (`impl Parent` in `parent/child.rs`) imports the
parent and is called by it without an import, which the graph does not count.
"""

import pathlib
import re
import sys

PATH = re.compile(
    r"(?<![A-Za-z_0-9:])((?:super::)+|crate::(?P<root>[a-z_]+)::|self::)?"
    r"((?:(?!super::)[a-z_0-9]+::)*)((?<=::)\{[^}]*\}|[A-Za-z_][A-Za-z_0-9]*|\*)"
)
CHILD = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+([a-z_0-9]+)\s*;", re.M)


def module_of(path, top):
    parts = list(path.relative_to(top.parent).with_suffix("").parts)
    return tuple(parts[:-1] if parts[-1] == "mod" else parts)


def main(folder):
    top = pathlib.Path(folder)
    files = sorted(top.rglob("*.rs"))
    modules = {module_of(f, top): f for f in files}

    def resolve(parts):
        for k in range(len(parts), 0, -1):
            if tuple(parts[:k]) in modules:
                return tuple(parts[:k])
        return None

    edges = {}
    for key, f in modules.items():
        text = "\n".join(line for line in f.read_text().split("\n") if not line.strip().startswith("//"))
        main_part, _, tests = text.partition("mod tests {")
        # Inside `mod tests` one `super::` less reaches this file.
        tests = re.sub(r"\b((?:super::)+)", lambda m: "super::" * (m.group(1).count("super") - 1) or "self::", tests)
        code = main_part + "\n" + tests
        children = set(CHILD.findall(code))
        out = set()
        for m in PATH.finditer(code):
            prefix, root, segments, last = m.group(1), m.group("root"), m.group(3), m.group(4)
            segments = [s for s in segments.split("::") if s]
            if prefix is None:
                if not segments or segments[0] not in children:
                    continue
                base = list(key) + segments
            elif prefix.startswith("super"):
                base = list(key[: len(key) - prefix.count("super")]) + segments
            elif prefix == "self::":
                base = list(key) + segments
            elif root == top.name:
                base = [top.name] + segments
            else:
                continue
            names = [g.strip().split("::")[0] for g in last[1:-1].split(",")] if last.startswith("{") else [last]
            for name in names:
                target = resolve(base + [name]) if name else resolve(base)
                if target and target != key:
                    out.add(target)
        edges[key] = out

    def show(k):
        return "/".join(k)

    for key in sorted(edges):
        print(f"{show(key):30} -> {', '.join(sorted(show(t) for t in edges[key])) or '-'}")
    state, stack, circles = {}, [], []

    def visit(u):
        state[u] = 1
        stack.append(u)
        for v in sorted(edges[u]):
            if state.get(v) == 1:
                circles.append(stack[stack.index(v) :] + [v])
            elif not state.get(v):
                visit(v)
        stack.pop()
        state[u] = 2

    for key in sorted(edges):
        if not state.get(key):
            visit(key)
    print("circles:", "none" if not circles else "")
    for c in circles:
        print("  " + " -> ".join(map(show, c)))
    return 1 if circles else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
