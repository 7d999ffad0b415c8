"""A C++ source file read without a compiler, for structure_counts.py: comments, literals and
preprocessor lines blanked (strip_code), the code tokenised, and FileModel's classes (methods,
fields, lines, access), function definitions with their lengths, comments and declarations
found by brace, parenthesis and template-bracket matching. The rules it follows are in
structure_counts.py's docstring."""

import re

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
