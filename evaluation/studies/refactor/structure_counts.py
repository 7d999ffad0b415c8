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
   name ends in Lock, such as MapWriteLock; a lock class's own constructors and assignments
   excluded) or carry a Clang thread-safety precondition (PKSLAM_REQUIRES,
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
import check_includes  # noqa: E402  (tests/layering/check_includes.py)

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

# Words that never name a function before its parameter list (a function pointer's `void (*f)`,
# `decltype(x)`, ...).
NOT_A_NAME = {"void", "bool", "char", "short", "int", "long", "float", "double", "signed",
              "unsigned", "auto", "const", "volatile", "decltype", "sizeof", "alignof", "alignas",
              "noexcept", "throw", "return", "static_assert", "__attribute__", "if", "for",
              "while", "switch", "catch", "new", "delete", "typeid", "static_cast",
              "dynamic_cast", "const_cast", "reinterpret_cast", "explicit", "requires"}
TRAILER_WORDS = {"const", "volatile", "noexcept", "override", "final", "throw", "&", "&&", "try"}
MACRO_RE = re.compile(r"^[A-Z][A-Z0-9]*_[A-Z0-9_]*$")  # PKSLAM_REQUIRES, PYBIND11_MODULE


# --- reading C++ -------------------------------------------------------------------------------

SPECIAL_RE = re.compile(r"""//|/\*|(?<![\w])(?:u8|[uUL])?R"|"|'|\n|#""")


def strip_code(text):
    """(code, comments): `text` with comments, literals' contents and preprocessor lines
    blanked (newlines kept, so line numbers hold), and the comments as
    (first line, last line, text, trailing: code before it on its line, kind '//' or '/*')."""
    out = []
    comments = []
    n = len(text)
    pos = 0  # text[:pos] is handled
    line = 1
    line_has_code = False

    def blanked(a, b):
        return re.sub(r"[^\n]", " ", text[a:b])

    while True:
        m = SPECIAL_RE.search(text, pos)
        if not m:
            out.append(text[pos:])
            break
        i = m.start()
        if text[pos:i].strip():
            line_has_code = True
        out.append(text[pos:i])
        tok = m.group(0)
        if tok == "\n":
            out.append("\n")
            line += 1
            line_has_code = False
            pos = i + 1
            continue
        if tok == "#":
            if line_has_code:  # stringizing inside a directive's continuation, or stray
                out.append("#")
                pos = i + 1
                continue
            j = i  # a preprocessor line, with its continuations and comments
            while j < n:
                if text[j] == "\n" and text[j - 1] != "\\":
                    break
                if text.startswith("/*", j):
                    end = text.find("*/", j + 2)
                    j = n if end < 0 else end + 2
                    continue
                if text.startswith("//", j):
                    while j < n and text[j] != "\n":
                        j += 1
                    break
                j += 1
            out.append(blanked(i, j))
            line += text.count("\n", i, j)
            pos = j
            continue
        if tok == "//":
            j = text.find("\n", i)
            j = n if j < 0 else j
            comments.append((line, line, text[i + 2:j], line_has_code, "//"))
            out.append(blanked(i, j))
            pos = j
            continue
        if tok == "/*":
            end = text.find("*/", i + 2)
            j = n if end < 0 else end + 2
            last = line + text.count("\n", i, j)
            comments.append((line, last, text[i + 2:max(i + 2, j - 2)], line_has_code, "/*"))
            out.append(blanked(i, j))
            line = last
            pos = j
            continue
        line_has_code = True
        if tok.endswith('R"'):
            rm = re.match(r'([^()\\\s]{0,16})\(', text[m.end():m.end() + 18])
            if rm:
                close = ")" + rm.group(1) + '"'
                start = m.end() + rm.end()
                end = text.find(close, start)
                j = n if end < 0 else end + len(close)
                out.append(text[i:start - 1] + blanked(start - 1, j - 1) + text[j - 1:j])
                line += text.count("\n", i, j)
                pos = j
                continue
            out.append(tok)  # not a raw string after all
            pos = m.end()
            continue
        if tok == "'" and _digit_separator(text, i):
            out.append(tok)
            pos = i + 1
            continue
        j = i + 1  # a string or character literal, to its closing quote or the line's end
        while j < n and text[j] != tok and text[j] != "\n":
            j += 2 if text[j] == "\\" else 1
        j = min(j, n)
        if j < n and text[j] == tok:
            out.append(tok + blanked(i + 1, j) + tok)
            pos = j + 1
        else:
            out.append(tok + blanked(i + 1, j))
            pos = j
    return "".join(out), comments


def _digit_separator(text, i):
    """Whether the ' at i separates digits (1'000'000) rather than opening a character."""
    k = i
    while k > 0 and (text[k - 1].isalnum() or text[k - 1] in "_."):
        k -= 1
    return k < i and text[k].isdigit()


TOKEN_RE = re.compile(r"[A-Za-z_]\w*|\d[\w.']*|::|->|\.\.\.|\"[^\"]*\"|'[^']*'|\S")


class Tok:
    __slots__ = ("text", "line")

    def __init__(self, text, line):
        self.text, self.line = text, line

    def __repr__(self):
        return f"{self.text}@{self.line}"


def tokenize(code):
    toks = []
    line, pos = 1, 0
    for m in TOKEN_RE.finditer(code):
        line += code.count("\n", pos, m.start())
        pos = m.start()
        toks.append(Tok(m.group(0), line))
    return toks


def is_ident(s):
    return bool(s) and (s[0].isalpha() or s[0] == "_")


BRACES = "{}"  # a consumed brace initialiser stands in a head as this token


def closing(toks, i, pair="{}"):
    """Index of the token closing the bracket toks[i] opens, pair: "{}", "()", "<>" or "[]"
    (the last token when unbalanced)."""
    depth = 0
    for k in range(i, len(toks)):
        t = toks[k].text
        if t == pair[0]:
            depth += 1
        elif t == pair[1]:
            depth -= 1
            if depth == 0:
                return k
    return len(toks) - 1


def match_brace(toks, i):
    return closing(toks, i, "{}")


def close_paren(head, k):
    return closing(head, k, "()")


def strip_template(head):
    """`head` without leading `template <...>` groups."""
    while len(head) >= 2 and head[0].text == "template" and head[1].text == "<":
        head = head[closing(head, 1, "<>") + 1:]
    return head


def top_level(head):
    """Yields (index, token) of `head` at parenthesis and template-bracket depth 0, up to its
    first top-level `=` (after which `<` may be a comparison)."""
    paren = angle = 0
    prev = None
    for k, t in enumerate(head):
        s = t.text
        if paren == 0 and angle == 0:
            yield k, t
            if s == "=":
                return
        if s in "([":
            paren += 1
        elif s in ")]":
            paren -= 1
        elif s == "<" and paren == 0 and prev is not None and (is_ident(prev) or prev == "::") \
                and prev != "operator":
            angle += 1
        elif s == ">" and paren == 0 and angle > 0:
            angle -= 1
        prev = s


def function_shape(head):
    """For a declaration head (template prefix removed): (name tokens, index of its parameter
    list's `(`) when it declares a function, else None."""
    for k, t in top_level(head):
        if t.text == "=":
            return None
        if t.text == "operator":
            # operator X (  /  operator() (  /  operator new[] (  /  operator Type (
            j = k + 1
            if j < len(head) and head[j].text == "(":
                j += 2  # operator()
            while j < len(head) and head[j].text != "(":
                j += 1
            if j >= len(head):
                return None
            start = k
            while start >= 2 and head[start - 1].text == "::" and is_ident(head[start - 2].text):
                start -= 2
            return head[start:j], j
        if t.text != "(" or k == 0:
            continue
        prev = head[k - 1].text
        if not is_ident(prev) or prev in NOT_A_NAME or MACRO_RE.match(prev):
            continue
        start = k - 1
        if start >= 1 and head[start - 1].text == "~":
            start -= 1
        while start >= 2 and head[start - 1].text == "::" and \
                (is_ident(head[start - 2].text) or head[start - 2].text == ">"):
            if head[start - 2].text == ">":  # Foo<T>::f
                depth, j = 0, start - 2
                while j >= 0:
                    if head[j].text == ">":
                        depth += 1
                    elif head[j].text == "<":
                        depth -= 1
                        if depth == 0:
                            break
                    j -= 1
                start = j - 1 if j >= 1 else 0
            else:
                start -= 2
        if start >= 1 and head[start - 1].text == "::":  # ::f
            start -= 1
        return head[start:k], k
    return None


def qualified_name(name_toks):
    """'A::B::f' from the name tokens (template arguments dropped)."""
    parts, depth = [], 0
    for t in name_toks:
        if t.text == "<":
            depth += 1
        elif t.text == ">":
            depth -= 1
        elif depth == 0:
            parts.append(t.text)
    return "".join(parts).lstrip(":")


def class_head(head):
    """The class name when `head` (before a `{`) opens a class/struct/union definition."""
    h = strip_template(head)
    k = 0
    while k < len(h) and h[k].text in ("typedef", "export"):
        k += 1
    if k >= len(h) or h[k].text not in ("class", "struct", "union"):
        return None
    k += 1
    name = None
    while k < len(h):
        s = h[k].text
        if s == "[" and k + 1 < len(h) and h[k + 1].text == "[":  # [[attribute]]
            k = closing(h, k, "[]") + 1
            continue
        if (MACRO_RE.match(s) or s in ("alignas", "__attribute__")) and k + 1 < len(h) \
                and h[k + 1].text == "(":
            k = close_paren(h, k + 1) + 1
            continue
        if MACRO_RE.match(s) and name is None and k + 1 < len(h) and is_ident(h[k + 1].text):
            k += 1  # an export macro without arguments
            continue
        if is_ident(s) and s != "final":
            name = s
            k += 1
            while k + 1 < len(h) and h[k].text == "::" and is_ident(h[k + 1].text):
                name += "::" + h[k + 1].text
                k += 2
            if k < len(h) and h[k].text == "<":  # a specialisation
                k = closing(h, k, "<>") + 1
            break
        return None
    if k < len(h) and h[k].text == "final":
        k += 1
    if k == len(h):
        return name or ""
    if h[k].text != ":":
        return None
    if any(t.text == "(" and not (MACRO_RE.match(h[j - 1].text) or h[j - 1].text == "decltype")
           for j, t in enumerate(h[k:], k)):
        return None
    return name or ""


class FileModel:
    """What one file defines: classes (headers), function definitions, function declarations
    and the comments."""

    def __init__(self, rel, text):
        self.rel = rel
        self.includes = set(re.findall(r'^\s*#\s*include\s+"([^"]+)"', text, re.M))
        code, self.comments = strip_code(text)
        self.toks = tokenize(code)
        self.classes = []     # dicts: name, qual, line, end, methods, fields (list of dicts)
        # dicts: name (qualified as written, enclosing classes first), line, end, in_class
        self.functions = []
        self.declarations = []  # function declarations and definitions: dicts name, head, cls
        self._scope(0, [], None)

    def _scope(self, i, classes, cls):
        """Reads declarations from toks[i] to the } that ends the scope; returns the index after
        it. `classes`: names of the enclosing classes; `cls`: the class record being read."""
        toks = self.toks
        head = []
        while i < len(toks):
            t = toks[i]
            s = t.text
            if s == "}":
                return i + 1
            if s == ";":
                self._statement(head, classes, cls, None)
                head = []
                i += 1
                continue
            if cls is not None and not head and s in ("public", "private", "protected") \
                    and i + 1 < len(toks) and toks[i + 1].text == ":":
                cls["access"] = s
                i += 2
                continue
            if s != "{":
                head.append(t)
                i += 1
                continue
            h = strip_template(head)
            texts = [x.text for x in h]
            if "namespace" in texts[:2] or (texts[:1] == ["extern"] and len(texts) == 2
                                             and texts[1].startswith('"')):
                i = self._scope(i + 1, classes, None)
                head = []
                continue
            if "enum" not in texts:
                name = class_head(head)
                if name is not None:
                    record = {"name": name, "qual": "::".join(classes + [name]) if name else "",
                              "line": head[0].line, "access": "public"
                              if any(x.text in ("struct", "union") for x in h[:3]) else "private",
                              "methods": 0, "fields": []}
                    i = self._scope(i + 1, classes + [name or "<anonymous>"], record)
                    record["end"] = toks[i - 1].line
                    if name:
                        self.classes.append(record)
                    head = [Tok("<class>", t.line)]
                    continue
                shape = function_shape(h)
                if shape is not None:
                    name_toks, k = shape
                    rest = h[close_paren(h, k) + 1:]
                    if self._is_body(rest):
                        end = match_brace(toks, i)
                        qual = "::".join(classes + [qualified_name(name_toks)])
                        self.functions.append({"name": qual, "line": head[0].line,
                                               "end": toks[end].line, "in_class": bool(classes)})
                        self._statement(head, classes, cls, shape)
                        head = []
                        i = end + 1
                        continue
            if cls is None and len(h) >= 3 and MACRO_RE.match(h[0].text) and h[1].text == "(" \
                    and close_paren(h, 1) == len(h) - 1:
                # a function a macro declares: PYBIND11_MODULE(pkslam, m) {...}
                end = match_brace(toks, i)
                self.functions.append({"name": f"{h[0].text}({h[2].text})", "line": head[0].line,
                                       "end": toks[end].line, "in_class": bool(classes)})
                head = []
                i = end + 1
                continue
            # A brace initialiser (or an enum's, or a member's in an initialiser list).
            end = match_brace(toks, i)
            head.append(Tok(BRACES, t.line))
            i = end + 1
        return i

    @staticmethod
    def _is_body(rest):
        """Whether a { after the parameter list and `rest` opens the function's body."""
        if not rest:
            return True
        texts = [t.text for t in rest]
        if ":" in texts and (texts.index(":") == 0 or texts[0] in TRAILER_WORDS):
            # constructor initialiser list: a { after a member name is that member's initialiser
            return texts[-1] in (")", BRACES)
        if "=" in texts:
            return False
        if "->" in texts:
            return True
        k = 0
        while k < len(rest):
            s = texts[k]
            if s in TRAILER_WORDS:
                k += 1
                if k < len(rest) and texts[k] == "(":
                    k = close_paren(rest, k) + 1
                continue
            if MACRO_RE.match(s):
                k += 1
                if k < len(rest) and texts[k] == "(":
                    k = close_paren(rest, k) + 1
                continue
            if s == "[" and k + 1 < len(rest) and texts[k + 1] == "[":  # [[attribute]]
                while k < len(rest) and texts[k] != "]":
                    k += 1
                k += 2
                continue
            return False
        return True

    def _statement(self, head, classes, cls, shape):
        """A declaration ended by ; (shape None) or a function definition (its shape)."""
        h = strip_template(head)
        if not h or h[0].text in ("<class>", "using", "typedef", "friend", "static_assert",
                                  "namespace", "enum", "class", "struct", "union", "template"):
            return
        if shape is None:
            shape = function_shape(h)
        if shape is not None:
            name_toks, k = shape
            deleted = any(a.text == "=" and b.text == "delete" for a, b in zip(h, h[1:]))
            self.declarations.append({"name": qualified_name(name_toks), "head": h, "paren": k,
                                      "cls": classes[-1] if classes else None,
                                      "line": h[0].line})
            if cls is not None and not deleted:
                cls["methods"] += 1
            return
        if cls is None:
            return
        cls["fields"].extend(data_members(h, cls["access"]))


def split_declarators(h):
    """The declarators of a data member declaration, each a list of tokens; the first keeps the
    shared type (`float u = 0, v = 0` -> [float u = 0], [v = 0])."""
    parts, cur = [], []
    paren = angle = 0
    after_eq = False
    prev = None
    for t in h:
        s = t.text
        if s in ("(", "["):
            paren += 1
        elif s in (")", "]"):
            paren -= 1
        elif paren == 0 and not after_eq and s == "<" and prev is not None \
                and (is_ident(prev) or prev == "::"):
            angle += 1
        elif paren == 0 and not after_eq and s == ">" and angle > 0:
            angle -= 1
        elif paren == 0 and angle == 0 and s == "=":
            after_eq = True
        elif paren == 0 and angle == 0 and s == ",":
            parts.append(cur)
            cur, after_eq, prev = [], False, None
            continue
        cur.append(t)
        prev = s
    parts.append(cur)
    return parts


def declarator(tokens):
    """(type and modifier tokens, name) of one declarator: the part before its initialiser,
    array bounds or bit-field width, macro annotations (PKSLAM_GUARDED_BY(m)) dropped."""
    ts = []
    for t in tokens:
        if t.text in ("=", BRACES, "[", ":"):
            break
        ts.append(t.text)
    clean, k = [], 0
    while k < len(ts):
        if MACRO_RE.match(ts[k]) and k + 1 < len(ts) and ts[k + 1] == "(":
            depth, k = 0, k + 1
            while k < len(ts):
                depth += (ts[k] == "(") - (ts[k] == ")")
                k += 1
                if depth == 0:
                    break
            continue
        clean.append(ts[k])
        k += 1
    if not clean or not is_ident(clean[-1]):
        return clean, None
    return clean[:-1], clean[-1]


def data_members(h, access):
    """The fields declared by a member declaration `h` (no function): name, access, static,
    const (constexpr; const object; a pointer const after its last *), ref."""
    texts = [t.text for t in h]
    static = "static" in texts
    constexpr = "constexpr" in texts
    parts = split_declarators(h)
    base, first_name = declarator(parts[0])
    # the type the later declarators share: the first one's up to its first * or &
    shared, depth = [], 0
    for s in base:
        depth += (s == "<") - (s == ">")
        if depth == 0 and s in ("*", "&", "&&"):
            break
        shared.append(s)
    fields = []
    for n, part in enumerate(parts):
        type_part, name = (base, first_name) if n == 0 else declarator(part)
        if n:
            type_part = shared + type_part
        if name is None:
            continue
        depth, stars, const_after_star, const_any, ref = 0, 0, False, False, False
        for s in type_part:
            if s == "<":
                depth += 1
            elif s == ">":
                depth -= 1
            elif depth == 0:
                if s == "*":
                    stars += 1
                    const_after_star = False
                elif s == "const":
                    const_any = const_after_star = True
                elif s in ("&", "&&"):
                    ref = True
        const = const_after_star if stars else const_any
        fields.append({"name": name, "access": access, "static": static,
                       "const": const or constexpr, "ref": ref})
    return fields


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
            if base != "operator=":
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
