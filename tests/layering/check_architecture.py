#!/usr/bin/python3
"""The architecture picture in docs/architecture.md (its first ```mermaid flowchart block) is
the CMake library graph, drawn. Rules:

  1. Every target of the graph is a node of the picture, and every node is a target of the
     graph. A node `id` names the target pkslam_<id> (core -> pkslam_core, bench ->
     pkslam_bench), except the few in NODE_TARGETS (apps -> the executable pkslam).
  2. Every drawn arrow `A --> B` ("A links B") is a direct link of A in CMake, not a merely
     transitive one.
  3. Every direct link A -> B in CMake is implied by the arrows: B is reachable from A following
     them. The picture may leave out a redundant arrow, never a dependency.

The graph: the pkslam_library() targets (their DEPS, read by check_includes.parse_libraries)
and the targets at the top that link them: the executable pkslam (apps/), the installed
library pkslam_api (api/) and the Python module _pkslam (python/), whose links are their
target_link_libraries() calls. A target_link_libraries() call on a pkslam_library target
counts as a link too. Links to anything else are not part of the graph: third-party
libraries and the interface wrappers pkslam_opencv, pkslam_nanoflann, pkslam_options. Left
out of the graph: the test-support libraries (check_includes.EXTRA: pkslam_map_model_testing,
pkslam_testsupport, which only tests link), and the executables of tests/, fuzz/ and examples/
(tests and tools, and examples/ builds against the installed package).

Prints each violation on one line and exits 1; prints a one-line summary otherwise.

  /usr/bin/python3 tests/layering/check_architecture.py [REPO]   (CTest: layering.architecture)
"""

import os
import re
import sys

sys.dont_write_bytecode = True  # importing check_includes must not leave __pycache__ in the tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_includes  # noqa: E402  (its parse_libraries is the one reading of pkslam_library)

DOC = "docs/architecture.md"
# Targets outside pkslam_library() that belong in the picture: name -> folder.
TOP_TARGETS = {"pkslam": "apps", "pkslam_api": "api", "_pkslam": "python"}
# Nodes whose target is not pkslam_<id>.
NODE_TARGETS = {"apps": "pkslam", "python": "_pkslam"}

# A node: id with an optional shape and label, e.g. core[core: util, ...], a(label), b{label}.
NODE = re.compile(r"\s*(\w+)\s*(?:\[[^\]]*\]|\([^)]*\)|\{[^}]*\})?\s*")
# Between nodes: an arrow (optionally labelled, -->|text|) or & (several nodes at one end).
JOINT = re.compile(r"(-->(?:\|[^|]*\|)?|&)")


def target_of(node):
    """The CMake target a node id stands for."""
    return NODE_TARGETS.get(node, "pkslam_" + node)


def cmake_text(path):
    """A CMakeLists.txt without its comments ('' if there is none)."""
    if not os.path.isfile(path):
        return ""
    with open(path) as f:
        return re.sub(r"#[^\n]*", "", f.read())


def linked_by_calls(text, target):
    """The words of every target_link_libraries(target ...) call in `text`."""
    words = []
    for m in re.finditer(r"target_link_libraries\(\s*(\S+)(.*?)\)", text, re.S):
        if m.group(1) == target:
            words += m.group(2).split()
    return words


def defines(text, target):
    """Whether `text` creates `target` (an executable, library or pybind11 module)."""
    pattern = (r"\b(?:add_executable|add_library|pybind11_add_module)\(\s*" + re.escape(target)
               + r"\s")
    return re.search(pattern, text) is not None


def library_graph(repo):
    """target -> {"folder": folder, "links": set of targets of the graph it links directly}."""
    graph = {}
    for name, lib in check_includes.parse_libraries(repo).items():
        if name not in check_includes.EXTRA:  # test support: only tests link it
            graph[name] = {"folder": lib["folder"], "links": set(lib["deps"])}
    for name, folder in TOP_TARGETS.items():
        if defines(cmake_text(os.path.join(repo, folder, "CMakeLists.txt")), name):
            graph[name] = {"folder": folder, "links": set()}
    for name, node in graph.items():
        text = cmake_text(os.path.join(repo, node["folder"], "CMakeLists.txt"))
        node["links"] |= set(linked_by_calls(text, name))
    for node in graph.values():
        node["links"] &= set(graph)  # third-party and wrapper targets are not drawn
    return graph


def mermaid_lines(doc_text):
    """(line number, line) of the first ```mermaid block that is a flowchart, header excluded;
    None when there is no such block."""
    lines = doc_text.split("\n")
    for start, line in enumerate(lines):
        if line.strip() != "```mermaid":
            continue
        body = []
        for number in range(start + 1, len(lines)):
            if lines[number].strip().startswith("```"):
                break
            body.append((number + 1, lines[number]))
        content = [(n, l) for n, l in body if l.strip() and not l.strip().startswith("%%")]
        if content and re.match(r"\s*(flowchart|graph)\b", content[0][1]):
            return content[1:]
    return None


def parse_statement(line):
    """A line `A --> B & C --> D` as its groups of node ids ([[A], [B, C], [D]]), or None when
    it is not made of nodes, arrows and &."""
    groups, pos = [[]], 0
    line = line.rstrip().rstrip(";")
    while True:
        m = NODE.match(line, pos)
        if not m:
            return None
        groups[-1].append(m.group(1))
        pos = m.end()
        if pos == len(line):
            return groups
        joint = JOINT.match(line, pos)
        if not joint:
            return None
        if joint.group(1) != "&":
            groups.append([])
        pos = joint.end()


def read_picture(repo):
    """(nodes: id -> line of first mention, arrows: (A, B) -> line, problems); nodes is None
    when there is no picture to check."""
    path = os.path.join(repo, DOC)
    if not os.path.isfile(path):
        return None, {}, [f"{DOC}: missing"]
    with open(path) as f:
        lines = mermaid_lines(f.read())
    if lines is None:
        return None, {}, [f"{DOC}: no ```mermaid flowchart block"]
    nodes, arrows, problems = {}, {}, []
    for number, line in lines:
        groups = parse_statement(line)
        if groups is None:
            problems.append(f"{DOC}:{number}: cannot read `{line.strip()}` (nodes are written "
                            "id or id[label], arrows A --> B)")
            continue
        for group in groups:
            for node in group:
                nodes.setdefault(node, number)
        for tails, heads in zip(groups, groups[1:]):
            for a in tails:
                for b in heads:
                    arrows.setdefault((a, b), number)
    return nodes, arrows, problems


def reachable(arrows, start):
    """The nodes reachable from `start` through one or more arrows."""
    seen, stack = set(), [b for (a, b) in arrows if a == start]
    while stack:
        n = stack.pop()
        if n not in seen:
            seen.add(n)
            stack.extend(b for (a, b) in arrows if a == n)
    return seen


def check(graph, nodes, arrows):
    """The violations of rules 1-3."""
    problems = []
    drawn = {target_of(n): n for n in nodes}
    for name in sorted(set(graph) - set(drawn)):  # rule 1: every target is drawn
        problems.append(f"{name} ({graph[name]['folder']}/CMakeLists.txt) has no node in {DOC}")
    for node, number in sorted(nodes.items(), key=lambda item: item[1]):  # rule 1: no others
        if target_of(node) not in graph:
            problems.append(f"{DOC}:{number}: node {node} is no target of the library graph "
                            f"({target_of(node)})")
    for (a, b), number in sorted(arrows.items(), key=lambda item: item[1]):  # rule 2
        ta, tb = target_of(a), target_of(b)
        if ta in graph and tb in graph and tb not in graph[ta]["links"]:
            problems.append(f"{DOC}:{number}: arrow {a} --> {b}, but {ta} does not link {tb} "
                            "directly")
    for name in sorted(graph):  # rule 3: no link hidden
        if name not in drawn:
            continue  # reported by rule 1
        shown = {target_of(n) for n in reachable(arrows, drawn[name])}
        for link in sorted(graph[name]["links"] - shown):
            problems.append(f"{name} links {link} ({graph[name]['folder']}/CMakeLists.txt), but "
                            f"{DOC} has no path of arrows from {drawn[name]} to "
                            f"{drawn.get(link, link)}")
    return problems


def main():
    own_repo = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    repo = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else own_repo)
    graph = library_graph(repo)
    nodes, arrows, problems = read_picture(repo)
    if nodes is not None:  # without a picture, every target would be reported missing
        problems += check(graph, nodes, arrows)
    for p in problems:
        print(p)
    if problems:
        return 1
    links = sum(len(node["links"]) for node in graph.values())
    print(f"architecture: {DOC} matches the CMake graph ({len(graph)} targets, {links} direct "
          f"links, {len(arrows)} arrows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
