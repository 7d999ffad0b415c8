#!/usr/bin/python3
"""Structure counts of the source tree, before and after a refactor (issue 42: the thread
classes and the map-change API). Prints a Markdown table; --json FILE writes the numbers.

  /usr/bin/python3 evaluation/studies/refactor/structure_counts.py [DIR]   (default: this repo)
  /usr/bin/python3 evaluation/studies/refactor/structure_counts.py --commit REV [--repo DIR]
  /usr/bin/python3 evaluation/studies/refactor/structure_counts.py --before REV --after REV \\
      [--repo DIR] [--json counts.json] [--details] [--no-duplicates]

A commit is exported with `git archive` into a temporary folder and counted there like a
folder. The counts are heuristics on the text (no compiler), the same rules for every tree:

Files. The library folders LIBRARY_FOLDERS (core io keyframe imu estimators sim dense viewer
map_model evaluation tracking mapping tracks rgbd loopclosing system apps api python), below
them every .h and .cc except: folders build*, .git, third_party and testing/; test and benchmark
sources (*_test.cc, *_benchmark.cc) and test-support headers (*_test_utils.h, *_testing.h).
Comments, string and character literals (raw strings too) and preprocessor lines are blanked
before the code is read, so a brace in them is not counted; declarations are then read by
brace, parenthesis and template-bracket matching.

1. Largest class. Every class/struct/union defined in a header (nested ones too, named
   Outer::Inner). methods: its member function declarations and inline definitions at its own
   level (constructors, destructors, operators, `= default` included; `= delete` and friends
   not); fields: its data members, static and const ones included (one per declarator,
   `float u = 0, v = 0;` is two); lines: the lines of its definition in the header (from its
   `class` line, or its `template` line, to the closing `};`) plus the lines of every
   out-of-line definition `Name::method(...) {...}` (first token of the definition to the
   closing brace) in a .cc or .h of the library folders. An out-of-line definition belongs to
   the class whose qualified name is the longest tail of its qualifier (`pkslam::Tracker::Track`
   -> Tracker); when two headers define a class of that name, the one the file #includes wins,
   then the one in the file's folder; otherwise it is left out (counted as "unattributed").
   The three with the most lines are reported.
2. Long functions. Every function definition with a body in a .cc (free functions, out-of-line
   members, members defined inside classes of the .cc, a body after a macro call such as
   `PYBIND11_MODULE(pkslam, m) {`; a lambda is part of the function around it; a macro is an
   all-caps name with an underscore): its length is the lines from the first token of the
   definition (its return type, or `template`) to its closing brace. Counted: over 100 lines
   and over 150 lines; those over 150 are listed by name and file:line.
3. Public mutable fields of the map classes KeyFrame, MapPoint, Map, Atlas, Frame (their
   definitions in headers below map_model/, top level): data members declared in a public
   section (class: private until `public:`; struct: public until `private:`/`protected:`)
   that are not static, not constexpr, not const (a pointer is const when `const` follows its
   last `*`: `const T* p` counts, `T* const p` does not) and not references. Members of nested
   types do not count.
4. Lock preconditions. "comments": comments in headers (a run of whole-line `//` comments on
   consecutive lines is one comment; a trailing `//` comment or a /* */ block is one) that say
   the caller holds a lock, by any of LOCK_COMMENT_PATTERNS: "requires [at least] the ... lock
   / mutex", "caller holds ... lock / mutex", "Atlas/map lock/mutex held" (not "no ... lock
   held"), "Atlas mutex shared / exclusive", "Shared [Atlas] lock." / "Exclusive lock." as a
   sentence, "need(s) the ... lock / mutex", "must hold / must be held ... lock / mutex",
   "holding the ... lock / mutex", "read / set / written / called under the ... lock /
   mutex". A comment counts once, however many sentences match. "checked": function
   declarations in headers (members and free functions) that take a lock object (a parameter
   whose type names std::unique_lock, shared_lock, lock_guard, scoped_lock or a type whose
   name ends in Lock, such as MapWriteLock; the members of a lock class and the Require*
   checks excluded) or carry a Clang thread-safety precondition (PKSLAM_REQUIRES,
   PKSLAM_REQUIRES_SHARED: core/util/annotated_mutex.h).
5. Duplicated header names: header file names used by two or more libraries, as
   tests/layering/check_includes.py reads them (imported: parse_libraries and header_names;
   all headers of a library's folder, test headers included).
6. Duplicate pairs: the first line of the `duplicates` command (the machine's tool, when it is
   on PATH) over the whole tree, tests included (in a git checkout the files git tracks and
   the untracked ones it does not ignore; in an exported commit every file): "N pairs of
   places"; a `*` marks a run it reported as incomplete. Without the tool, or with
   --no-duplicates: n/a.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
OWN_REPO = os.path.realpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(OWN_REPO, "tests", "layering"))
sys.path.insert(0, HERE)
import check_includes  # noqa: E402  (tests/layering/check_includes.py)
from cpp_model import FileModel, close_paren, closing, declarator, is_ident  # noqa: E402

LIBRARY_FOLDERS = ("core io keyframe imu estimators sim dense viewer map_model evaluation tracking "
                   "mapping tracks rgbd loopclosing system apps api python").split()
MAP_CLASSES = ("KeyFrame", "MapPoint", "Map", "Atlas", "Frame")
LONG, VERY_LONG = 100, 150
TOP_CLASSES = 3

LOCK_COMMENT_PATTERNS = [
    r"\brequires\s+(?:at\s+least\s+)?the\s+(?:[\w'()-]+\s+){0,3}?(?:lock|mutex)\b",
    r"\bcallers?\s+(?:must\s+)?(?:holds?|holding)\b[^.;]{0,60}?\b(?:lock|mutex)\b",
    r"(?<!\bno )\b(?:atlas|map)\s+(?:lock|mutex)\s+held\b",
    r"\batlas\s+(?:lock|mutex)\s+(?:shared|exclusive)\b",
    r"(?:^|[.;:]\s)(?:shared|exclusive)\s+(?:atlas\s+)?(?:lock|mutex)\s*[.;)]",
    r"\bneeds?\s+the\s+(?:[\w'-]+\s+){0,2}?(?:lock|mutex)\b",
    r"\bmust\s+(?:hold|be\s+held)\b[^.;]{0,60}?\b(?:lock|mutex)\b",
    r"\b(?:lock|mutex)\b[^.;]{0,40}?\bmust\s+be\s+held\b",
    r"\bholding\s+(?:the|a|an)\s+(?:[\w'()-]+\s+){0,3}?(?:lock|mutex)\b",
    r"\b(?:read|set|written|called)\s+under\s+(?:the|a|an)\s+(?:[\w'-]+\s+){0,2}?"
    r"(?:lock|mutex)\b",
]
LOCK_COMMENT_RE = re.compile("|".join(LOCK_COMMENT_PATTERNS), re.I)
STD_LOCKS = {"unique_lock", "shared_lock", "lock_guard", "scoped_lock"}
REQUIRES_RE = re.compile(r"^PKSLAM_REQUIRES(?:_SHARED)?$")

# --- the tree -----------------------------------------------------------------------------------

def is_skipped_file(rel):
    base = os.path.basename(rel)
    return (base.endswith(("_test.cc", "_benchmark.cc", "_test_utils.h", "_testing.h"))
            or "/testing/" in "/" + rel)


def library_files(repo):
    """Relative paths of the library folders' .h and .cc files that are counted."""
    found = []
    for folder in LIBRARY_FOLDERS:
        for root, dirs, files in os.walk(os.path.join(repo, folder)):
            dirs[:] = sorted(d for d in dirs if d not in (".git", "third_party", "testing")
                             and not d.startswith("build"))
            for f in sorted(files):
                if f.endswith((".h", ".cc")):
                    rel = os.path.relpath(os.path.join(root, f), repo)
                    if not is_skipped_file(rel):
                        found.append(rel)
    return found


def read_models(repo):
    models = {}
    for rel in library_files(repo):
        with open(os.path.join(repo, rel), errors="replace") as fh:
            models[rel] = FileModel(rel, fh.read())
    return models


def each(models, ending):
    """(path, model) of the files whose name ends with `ending`."""
    return ((rel, m) for rel, m in models.items() if rel.endswith(ending))


def largest_classes(models, top=TOP_CLASSES):
    by_qual = {}
    rows = []
    for rel, m in each(models, ".h"):
        for c in m.classes:
            row = {"name": c["qual"], "header": rel, "line": c["line"], "methods": c["methods"],
                   "fields": len(c["fields"]), "header_lines": c["end"] - c["line"] + 1,
                   "outside_lines": 0, "outside_definitions": 0, "files": set()}
            rows.append(row)
            by_qual.setdefault(c["qual"], []).append(row)
    unattributed = 0
    for rel, m in models.items():
        for f in m.functions:
            parts = f["name"].split("::")
            if f["in_class"] or len(parts) < 2:
                continue
            owner_row = None
            for start in range(len(parts) - 1):
                candidates = by_qual.get("::".join(parts[start:-1]))
                if candidates:
                    owner_row = pick_class(candidates, rel, m.includes)
                    if owner_row is None:
                        unattributed += 1
                    break
            if owner_row is None:
                continue
            owner_row["outside_lines"] += f["end"] - f["line"] + 1
            owner_row["outside_definitions"] += 1
            owner_row["files"].add(rel)
    for row in rows:
        row["lines"] = row["header_lines"] + row["outside_lines"]
        row["files"] = sorted(row["files"])
    rows.sort(key=lambda r: (-r["lines"], r["name"], r["header"]))
    return rows[:top], unattributed


def pick_class(candidates, rel, includes):
    if len(candidates) == 1:
        return candidates[0]
    included = [c for c in candidates if c["header"] in includes or c["header"] == rel]
    if len(included) == 1:
        return included[0]
    same_folder = [c for c in candidates if os.path.dirname(c["header"]) == os.path.dirname(rel)]
    if len(same_folder) == 1:
        return same_folder[0]
    return None


def long_functions(models):
    found = []
    for rel, m in each(models, ".cc"):
        for f in m.functions:
            length = f["end"] - f["line"] + 1
            if length > LONG:
                found.append({"name": f["name"], "file": rel, "line": f["line"], "lines": length})
    found.sort(key=lambda f: (-f["lines"], f["file"], f["line"]))
    return found


def map_class_fields(models):
    counts = {}
    for rel, m in each(models, ".h"):
        if not rel.startswith("map_model/"):
            continue
        for c in m.classes:
            if c["qual"] in MAP_CLASSES:
                fields = [f["name"] for f in c["fields"] if f["access"] == "public"
                          and not f["static"] and not f["const"] and not f["ref"]]
                counts.setdefault(c["qual"], []).extend(fields)
    return {name: counts.get(name, []) for name in MAP_CLASSES if name in counts}


def lock_comments(models):
    found = []
    for rel, m in each(models, ".h"):
        blocks = []
        for first, last, text, trailing, kind in m.comments:
            if (kind == "//" and not trailing and blocks and blocks[-1]["open"]
                    and blocks[-1]["last"] == first - 1):
                blocks[-1]["text"] += " " + text.strip()
                blocks[-1]["last"] = last
                continue
            blocks.append({"first": first, "last": last, "text": text.strip(),
                           "open": kind == "//" and not trailing})
        for b in blocks:
            text = re.sub(r"\s+", " ", b["text"])
            mm = LOCK_COMMENT_RE.search(text)
            if mm:
                found.append({"file": rel, "line": b["first"], "says": mm.group(0).strip()})
    return found


def lock_signatures(models):
    found = []
    for rel, m in each(models, ".h"):
        for d in m.declarations:
            h, k = d["head"], d["paren"]
            end = close_paren(h, k)
            params = h[k + 1:end]
            base = d["name"].split("::")[-1]
            why = None
            # A lock class's own members (constructors converting from another lock) and the
            # checks that throw without a lock are not preconditions.
            if base != "operator=" and not (d["cls"] or "").endswith("Lock") and \
                    not base.startswith("Require"):
                for p in split_params(params):
                    locks = [t.text for t in p if t.text in STD_LOCKS or
                             (is_ident(t.text) and t.text.endswith("Lock") and t.text != base)]
                    if locks and not (d["cls"] == locks[0]):
                        why = "lock parameter " + locks[0]
                        break
            if why is None:
                for t in h[end + 1:]:
                    if REQUIRES_RE.match(t.text):
                        why = t.text
                        break
            if why:
                found.append({"file": rel, "line": d["line"], "function": d["name"], "by": why})
    return found


def split_params(params):
    out, cur, depth = [], [], 0
    for t in params:
        if t.text in "(<[{":
            depth += 1
        elif t.text in ")>]}":
            depth -= 1
        if t.text == "," and depth == 0:
            out.append(cur)
            cur = []
        else:
            cur.append(t)
    if cur:
        out.append(cur)
    return out


def duplicated_header_names(repo):
    libs = check_includes.parse_libraries(repo)
    by_name = check_includes.header_names(repo, libs)
    return {name: sorted(owners.values()) for name, owners in sorted(by_name.items())
            if len(owners) > 1}


def duplicate_pairs(repo, seconds):
    tool = shutil.which("duplicates")
    if tool is None:
        return None
    try:
        run = subprocess.run([tool, "--repo", repo, "--seconds", str(seconds)],
                             capture_output=True, text=True, timeout=seconds + 60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    lines = run.stdout.splitlines()
    incomplete = any(line.startswith("incomplete:") for line in lines)
    first = lines[0] if lines else ""
    m = re.match(r"(\d+) pairs? of places", first)
    if m:
        pairs = int(m.group(1))
    elif first.startswith("no duplicates"):
        pairs = 0
    else:
        return None
    files = re.search(r"\((\d+) files? read\)", first)
    return {"pairs": pairs, "files": int(files.group(1)) if files else None,
            "incomplete": incomplete, "summary": first}


def count_tree(repo, duplicates=True, duplicate_seconds=120):
    models = read_models(repo)
    classes, unattributed = largest_classes(models)
    functions = long_functions(models)
    fields = map_class_fields(models)
    comments = lock_comments(models)
    checked = lock_signatures(models)
    headers = duplicated_header_names(repo)
    return {
        "files": len(models),
        "largest_classes": classes,
        "unattributed_definitions": unattributed,
        "functions_over_100": sum(f["lines"] > LONG for f in functions),
        "functions_over_150": sum(f["lines"] > VERY_LONG for f in functions),
        "long_functions": functions,
        "map_public_mutable_fields": sum(len(v) for v in fields.values()),
        "map_public_mutable_fields_by_class": fields,
        "lock_comments": len(comments),
        "lock_comment_places": comments,
        "lock_checked": len(checked),
        "lock_checked_by_parameter": sum(c["by"].startswith("lock parameter") for c in checked),
        "lock_checked_by_annotation": sum(not c["by"].startswith("lock parameter")
                                          for c in checked),
        "lock_checked_places": checked,
        "duplicated_header_names": len(headers),
        "duplicated_header_name_list": headers,
        "duplicates": duplicate_pairs(repo, duplicate_seconds) if duplicates else None,
    }


# --- commits ------------------------------------------------------------------------------------

def export_commit(repo, rev, into):
    """Writes the tree of `rev` below `into` (git archive); returns its short hash."""
    short = subprocess.run(["git", "-C", repo, "rev-parse", "--short", rev + "^{commit}"],
                           capture_output=True, text=True, check=True).stdout.strip()
    proc = subprocess.Popen(["git", "-C", repo, "archive", "--format=tar", rev],
                            stdout=subprocess.PIPE)
    with tarfile.open(fileobj=proc.stdout, mode="r|") as tar:
        if hasattr(tarfile, "data_filter"):
            tar.extractall(into, filter="data")
        else:
            tar.extractall(into)
    proc.stdout.close()
    if proc.wait() != 0:
        raise SystemExit(f"git archive {rev} failed")
    return short


def count_commit(repo, rev, **kw):
    with tempfile.TemporaryDirectory(prefix="pkslam_structure_") as tmp:
        short = export_commit(repo, rev, tmp)
        counts = count_tree(tmp, **kw)
    label = rev if rev.startswith(short) else f"{rev} ({short})"
    return label, counts


# --- output -------------------------------------------------------------------------------------

def class_cell(row):
    if row is None:
        return "-"
    return f"{row['name']}: {row['methods']} / {row['fields']} / {row['lines']}"


def dup_cell(d):
    if d is None:
        return "n/a"
    return f"{d['pairs']}{'*' if d['incomplete'] else ''}"


def table(columns):
    """Markdown: one row per count, one column per tree."""
    labels = [label for label, _ in columns]
    rows = []
    for k in range(TOP_CLASSES):
        rows.append((f"largest class {k + 1}: methods / fields / lines",
                     [class_cell(c["largest_classes"][k] if k < len(c["largest_classes"]) else None)
                      for _, c in columns]))
    rows.append((f"functions over {LONG} lines",
                 [str(c["functions_over_100"]) for _, c in columns]))
    rows.append((f"functions over {VERY_LONG} lines",
                 [str(c["functions_over_150"]) for _, c in columns]))
    rows.append(("public mutable fields on map classes (" + ", ".join(MAP_CLASSES) + ")",
                 [f"{c['map_public_mutable_fields']} ("
                  + ", ".join(f"{n} {len(v)}" for n, v in
                              c["map_public_mutable_fields_by_class"].items()) + ")"
                  for _, c in columns]))
    rows.append(("lock preconditions as comments", [str(c["lock_comments"]) for _, c in columns]))
    rows.append(("lock preconditions in signatures (lock parameter + PKSLAM_REQUIRES)",
                 [f"{c['lock_checked']} ({c['lock_checked_by_parameter']} + "
                  f"{c['lock_checked_by_annotation']})" for _, c in columns]))
    rows.append(("duplicated header names",
                 [str(c["duplicated_header_names"]) for _, c in columns]))
    rows.append(("duplicate pairs (`duplicates`)", [dup_cell(c["duplicates"]) for _, c in columns]))
    out = ["| count | " + " | ".join(labels) + " |", "|---" * (len(labels) + 1) + "|"]
    out += ["| " + name + " | " + " | ".join(cells) + " |" for name, cells in rows]
    return "\n".join(out)


def details(columns, full):
    out = []
    for label, c in columns:
        out.append(f"\n{label}: {c['files']} files read")
        for r in c["largest_classes"]:
            out.append(f"  class {r['name']} ({r['header']}:{r['line']}): "
                       f"{r['header_lines']} header "
                       f"lines + {r['outside_lines']} in {r['outside_definitions']} out-of-line "
                       f"definitions ({', '.join(r['files']) or 'none'})")
        for f in c["long_functions"]:
            if f["lines"] > VERY_LONG:
                out.append(f"  over {VERY_LONG}: {f['name']} {f['file']}:{f['line']} "
                           f"{f['lines']} lines")
        for name, places in c["duplicated_header_name_list"].items():
            out.append(f"  header name {name}: {', '.join(places)}")
        if full:
            for f in c["long_functions"]:
                if f["lines"] <= VERY_LONG:
                    out.append(f"  over {LONG}: {f['name']} {f['file']}:{f['line']} "
                               f"{f['lines']} lines")
            for n, v in c["map_public_mutable_fields_by_class"].items():
                out.append(f"  public mutable fields of {n}: {', '.join(v) or 'none'}")
            for p in c["lock_comment_places"]:
                out.append(f"  lock comment {p['file']}:{p['line']}: \"{p['says']}\"")
            for p in c["lock_checked_places"]:
                out.append(f"  checked {p['file']}:{p['line']} {p['function']}: {p['by']}")
        if c["duplicates"] is not None:
            out.append(f"  duplicates: {c['duplicates']['summary']}")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir", nargs="?", help="a source tree (default: this repository)")
    ap.add_argument("--commit", help="count this commit of --repo instead of a folder")
    ap.add_argument("--before", help="with --after: two commits side by side")
    ap.add_argument("--after")
    ap.add_argument("--repo", help="the git repository of the commits (default: DIR or this one)")
    ap.add_argument("--json", help="write the counts to this file")
    ap.add_argument("--details", action="store_true",
                    help="also list every long function, field, lock comment and signature")
    ap.add_argument("--no-duplicates", action="store_true", help="do not run `duplicates`")
    ap.add_argument("--duplicate-seconds", type=int, default=120)
    a = ap.parse_args(argv)
    if bool(a.before) != bool(a.after):
        ap.error("--before and --after go together")
    if a.commit and a.before:
        ap.error("--commit or --before/--after, not both")
    kw = {"duplicates": not a.no_duplicates, "duplicate_seconds": a.duplicate_seconds}
    repo = os.path.abspath(a.repo or a.dir or OWN_REPO)
    if a.before:
        columns = [count_commit(repo, a.before, **kw), count_commit(repo, a.after, **kw)]
    elif a.commit:
        columns = [count_commit(repo, a.commit, **kw)]
    else:
        tree = os.path.abspath(a.dir or OWN_REPO)
        label = "working tree" if os.path.realpath(tree) == OWN_REPO else tree
        columns = [(label, count_tree(tree, **kw))]
    print(table(columns))
    print(details(columns, a.details))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"columns": [{"label": label, "counts": c} for label, c in columns]}, fh,
                      indent=1, default=str)
            fh.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
