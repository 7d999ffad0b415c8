#!/usr/bin/python3
"""Dependencies point one way: every `#include "folder/..."` of a library's sources must name a
file of the library itself or of a library it links (DEPS, transitively), and the DEPS graph has
no cycle. Tests and benchmarks may also use their TEST_DEPS. And no header name is used by two
libraries (`#include "io/trajectory.h"` beside `#include "sim/trajectory.h"` reads as one
thing). Reads the pkslam_library() calls of the CMakeLists.txt files; prints each violation as
FILE:LINE (or the two files) and exits 1.

  /usr/bin/python3 tests/layering/check_includes.py [REPO]      (CTest: layering.includes)
"""

import os
import re
import sys

# Targets outside pkslam_library(): the test-support libraries and the executable at the top.
EXTRA = {
    "pkslam_map_model_testing": {"folder": "map_model/testing", "deps": ["pkslam_map_model"]},
    "pkslam_testsupport": {"folder": "tests/support", "deps": []},
}
SKIP_FOLDERS = {"build", "build-address", "build-fuzz", "build-thread", ".git", "third_party"}
TOP_FOLDERS = {"apps", "tests", "fuzz", "examples", "api", "python"}  # may include anything
# Header names two libraries may share: none since issue 42 renamed the last five. A name put
# here that is no longer shared is reported too, so the list cannot go stale.
SHARED_HEADER_NAMES = set()


def parse_libraries(repo):
    libs = {}
    for root, dirs, files in os.walk(repo):
        dirs[:] = [d for d in dirs if d not in SKIP_FOLDERS and not d.startswith("build")]
        if "CMakeLists.txt" not in files:
            continue
        with open(os.path.join(root, "CMakeLists.txt")) as fh:
            text = fh.read()
        text = re.sub(r"#[^\n]*", "", text)
        for m in re.finditer(r"pkslam_library\(\s*(\w+)(.*?)\)", text, re.S):
            name, body = m.group(1), m.group(2)
            sections, current = {}, None
            for word in body.split():
                if word in ("SOURCES", "DEPS", "TESTS", "TEST_DEPS", "BENCHMARKS", "LABEL"):
                    current = word
                    sections.setdefault(word, [])
                elif current:
                    sections[current].append(word)
            folder = os.path.relpath(root, repo)
            libs[name] = {
                "folder": folder,
                "deps": [d for d in sections.get("DEPS", []) if d.startswith("pkslam_")],
                "test_deps": [d for d in sections.get("TEST_DEPS", []) if d.startswith("pkslam_")],
                "tests": {os.path.normpath(os.path.join(folder, f))
                          for f in sections.get("TESTS", []) + sections.get("BENCHMARKS", [])},
            }
    for name, extra in EXTRA.items():
        libs.setdefault(name, {"folder": extra["folder"], "deps": extra["deps"], "test_deps": [],
                               "tests": set()})
    return libs


def find_cycle(libs):
    state = {}

    def visit(n, path):
        state[n] = 1
        for d in libs.get(n, {}).get("deps", []):
            if d not in libs:
                continue
            if state.get(d) == 1:
                return path + [n, d]
            if d not in state:
                cycle = visit(d, path + [n])
                if cycle:
                    return cycle
        state[n] = 2
        return None

    for n in libs:
        if n not in state:
            cycle = visit(n, [])
            if cycle:
                return cycle
    return None


def closure(libs, names):
    seen, stack = set(), list(names)
    while stack:
        n = stack.pop()
        if n in seen or n not in libs:
            continue
        seen.add(n)
        stack.extend(libs[n]["deps"])
    return seen


def owner(libs, path):
    """The library whose folder is the longest prefix of `path` (None: top-level code)."""
    best, best_len = None, -1
    for name, lib in libs.items():
        folder = lib["folder"]
        if (path == folder or path.startswith(folder + "/")) and len(folder) > best_len:
            best, best_len = name, len(folder)
    return best


def header_names(repo, libs):
    """Header file name -> {library: its path}: every .h below a library's folder, owned by the
    library whose folder is the longest prefix (test headers included). Also read by
    evaluation/studies/refactor/structure_counts.py."""
    by_name = {}
    for name, lib in libs.items():
        for root, dirs, files in os.walk(os.path.join(repo, lib["folder"])):
            dirs[:] = [d for d in dirs if d not in SKIP_FOLDERS]
            for f in files:
                if not f.endswith(".h"):
                    continue
                rel = os.path.relpath(os.path.join(root, f), repo)
                if owner(libs, rel) == name:
                    by_name.setdefault(f, {}).setdefault(name, rel)
    return by_name


def shared_header_names(by_name, allowed):
    """A header name used by two libraries (by_name: name -> {library: its header}), unless
    `allowed`; and a name in `allowed` that is not shared."""
    problems = []
    for header, owners in sorted(by_name.items()):
        shared = len(owners) > 1
        if shared and header not in allowed:
            problems.append(f"header name {header} is used by {len(owners)} libraries: "
                            + ", ".join(sorted(owners.values())))
    for header in sorted(allowed):
        if len(by_name.get(header, {})) < 2:
            problems.append(f"check_includes.py: SHARED_HEADER_NAMES lists {header}, which no "
                            "two libraries share any more: take it off")
    return problems


def main():
    own_repo = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    repo = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else own_repo)
    libs = parse_libraries(repo)
    problems = []
    cycle = find_cycle(libs)
    if cycle:
        problems.append("CMake: dependency cycle " + " -> ".join(cycle))
    include = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
    # Test-support headers beside the sources (scenario builders, test data): headers that
    # only tests, benchmarks or other such headers include.
    includers = {}
    tests = set()
    for name, lib in libs.items():
        for root, dirs, files in os.walk(os.path.join(repo, lib["folder"])):
            dirs[:] = [d for d in dirs if d not in SKIP_FOLDERS]
            for f in files:
                if not f.endswith((".cc", ".h")):
                    continue
                rel = os.path.relpath(os.path.join(root, f), repo)
                if rel in lib["tests"] or f.endswith(("_test.cc", "_benchmark.cc")):
                    tests.add(rel)
                with open(os.path.join(repo, rel), errors="replace") as fh:
                    for line in fh:
                        m = include.match(line)
                        if m:
                            includers.setdefault(m.group(1), set()).add(rel)
    changed = True
    while changed:
        changed = False
        for header, by in includers.items():
            if header not in tests and header.endswith(".h") and by and by <= tests:
                tests.add(header)
                changed = True
    checked = 0
    for name, lib in sorted(libs.items()):
        base = os.path.join(repo, lib["folder"])
        allowed = closure(libs, [name])
        allowed_tests = allowed | closure(libs, lib["test_deps"]) | {"pkslam_testsupport"}
        for root, dirs, files in os.walk(base):
            dirs[:] = [d for d in dirs if d not in SKIP_FOLDERS]
            for f in files:
                if not f.endswith((".cc", ".h")):
                    continue
                rel = os.path.relpath(os.path.join(root, f), repo)
                if owner(libs, rel) != name or rel.split("/")[0] in TOP_FOLDERS:
                    continue
                is_test = rel in tests or "/testing/" in rel
                ok = allowed_tests if is_test else allowed
                checked += 1
                with open(os.path.join(repo, rel), errors="replace") as fh:
                    for number, line in enumerate(fh, 1):
                        m = include.match(line)
                        if not m:
                            continue
                        target = m.group(1)
                        if not os.path.exists(os.path.join(repo, target)):
                            continue  # a generated or third-party header
                        to = owner(libs, target)
                        if to is not None and to not in ok:
                            problems.append(f"{rel}:{number}: includes {target} of {to}, which "
                                            f"{name} does not link"
                                            + (" (test)" if is_test else ""))
    # The allowance describes this repository (the self-test's repositories have none).
    allowed = SHARED_HEADER_NAMES if os.path.realpath(repo) == own_repo else set()
    problems += shared_header_names(header_names(repo, libs), allowed)
    for p in problems:
        print(p)
    print(f"layering: {checked} files of {len(libs)} libraries checked, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
