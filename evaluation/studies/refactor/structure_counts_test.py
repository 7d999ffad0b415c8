"""Tests of structure_counts.py on small hand-made source trees: each count on code whose answer
is known (a class with an out-of-line definition, 120- and 160-line functions with braces in
comments and literals, public and private fields, lock comments and a lock parameter, two
libraries sharing a header name), and two commits of a git repository side by side."""
import contextlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest
from unittest import mock

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import structure_counts as sc  # noqa: E402
import cpp_model  # noqa: E402


def write(root, rel, text):
    path = os.path.join(root, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(textwrap.dedent(text).lstrip("\n"))


# Lines a brace counter that ignored comments and literals would miscount.
FILLER = [
    "  x += 1;  // } a closing brace in a comment",
    "  if (x > 3) { x -= 1; }",
    '  const char* s = "{{ not a brace";',
    "  char c = '{';",
    "  /* } */ x ^= 2;",
    "  auto f = [](int y) { return y + 1; };",
    '  const char* r = R"raw(}})raw";',
    "  x = 1'000 + x + (c == '}');",
    '  const char* e = "\\"}";',
    "  /* a block comment",
    "     spanning lines { { */",
]


def function(name, lines):
    """A function definition of exactly `lines` lines."""
    body = [f"int {name}(int x) {{"]
    body += [FILLER[k % len(FILLER)] for k in range(lines - 3)]
    if body[-1] == FILLER[9]:  # do not end inside the block comment
        body[-1] = "  x += 2;"
    body += ["  return x;", "}"]
    assert len(body) == lines
    return "\n".join(body) + "\n"


WIDGET_H = """
#pragma once
#include <functional>

namespace pkslam {

// A widget.
class Widget {
 public:
  Widget();
  ~Widget();
  Widget(const Widget&) = delete;
  int Size() const { return size_; }
  void Run(int n);
  template <typename T>
  void Put(T x);
  static Widget Make();
  std::function<void(int)> callback;

 private:
  int size_ = 0;
  float u_ = 0, v_ = 0;
  static constexpr int kMax = 3;
  struct Inner {
    int a;
    void f();
  };
  Mutex mutex_;
  int guarded_ PKSLAM_GUARDED_BY(mutex_){};
};

struct Gadget {
  int a;
};

}  // namespace pkslam
"""
WIDGET_CC = """
#include "tracking/widget.h"

namespace pkslam {

Widget::Widget() : size_(1), u_{2} {
  // a } in a comment
}

Widget::~Widget() = default;

void Widget::Run(int n) {
  const char* s = "}}}";
  for (int i = 0; i < n; ++i) {
    size_ += i;
  }
}

void Widget::Inner::f() {}

}  // namespace pkslam
"""


class ClassTest(unittest.TestCase):
    def test_largest_class(self):
        with tempfile.TemporaryDirectory() as root:
            write(root, "tracking/widget.h", WIDGET_H)
            write(root, "tracking/widget.cc", WIDGET_CC)
            counts = sc.count_tree(root, duplicates=False)
        top = counts["largest_classes"]
        self.assertEqual(top[0]["name"], "Widget")
        # Constructor, destructor, Size, Run, Put, Make (the deleted copy is no method).
        self.assertEqual(top[0]["methods"], 6)
        # callback, size_, u_, v_, kMax, mutex_, guarded_ (Inner's a is Inner's).
        self.assertEqual(top[0]["fields"], 7)
        self.assertEqual(top[0]["header_lines"], 29 - 7 + 1)  # `class Widget {` .. `};`
        self.assertEqual(top[0]["outside_lines"], 3 + 6)  # the constructor and Run
        self.assertEqual(top[0]["lines"], 23 + 9)
        self.assertEqual(top[0]["files"], ["tracking/widget.cc"])
        by_name = {r["name"]: r for r in top}
        self.assertEqual(by_name["Widget::Inner"]["methods"], 1)
        self.assertEqual(by_name["Widget::Inner"]["fields"], 1)
        self.assertEqual(by_name["Widget::Inner"]["outside_lines"], 1)
        self.assertEqual([r["name"] for r in top], ["Widget", "Widget::Inner", "Gadget"])

    def test_same_class_name_in_two_headers(self):
        with tempfile.TemporaryDirectory() as root:
            write(root, "io/a/thing.h", "class Thing {\n  void f();\n};\n")
            write(root, "io/b/thing.h", "class Thing {\n  void f();\n  void g();\n};\n")
            write(root, "io/b/thing.cc", '#include "io/b/thing.h"\nvoid Thing::f() {\n}\n')
            write(root, "io/c/other.cc", "void Thing::g() {\n}\n")  # includes neither
            counts = sc.count_tree(root, duplicates=False)
        top = counts["largest_classes"]
        self.assertEqual((top[0]["header"], top[0]["lines"]), ("io/b/thing.h", 4 + 2))
        self.assertEqual((top[1]["header"], top[1]["lines"]), ("io/a/thing.h", 3))
        self.assertEqual(counts["unattributed_definitions"], 1)


class FunctionTest(unittest.TestCase):
    def test_long_functions(self):
        with tempfile.TemporaryDirectory() as root:
            write(root, "core/long.cc",
                  "#include <x>\n#define BRACE {\n\nnamespace pkslam {\nnamespace {\n\n"
                  + function("Short", 20) + "\n" + function("Medium", 120) + "\n"
                  + function("Long", 160) + "\n}  // namespace\n}  // namespace pkslam\n")
            # Not counted: tests, testing/ folders, build folders, third_party.
            write(root, "core/long_test.cc", function("InTest", 200))
            write(root, "core/testing/helper.cc", function("InTesting", 200))
            write(root, "core/build-x/gen.cc", function("InBuild", 200))
            write(root, "core/third_party/lib.cc", function("InThirdParty", 200))
            write(root, "examples/example.cc", function("InExample", 200))
            counts = sc.count_tree(root, duplicates=False)
        self.assertEqual(counts["functions_over_100"], 2)
        self.assertEqual(counts["functions_over_150"], 1)
        self.assertEqual([(f["name"], f["lines"]) for f in counts["long_functions"]],
                         [("Long", 160), ("Medium", 120)])
        self.assertEqual(counts["files"], 1)

    def test_members_and_initialiser_lists(self):
        code = ("struct Local {\n  int Get() {\n" + "    x = 1;\n" * 101 + "  }\n  int x;\n};\n"
                "Foo::Foo(int a) : a_(a), b_{a, 2}, c_{} {\n" + "  a_++;\n" * 100 + "}\n"
                "const auto kTable = [] {\n" + "  int y = 0;\n" * 120 + "  return 1;\n}();\n")
        with tempfile.TemporaryDirectory() as root:
            write(root, "io/x.cc", code)
            counts = sc.count_tree(root, duplicates=False)
        # The lambda's initialiser is no function definition.
        self.assertEqual([(f["name"], f["lines"]) for f in counts["long_functions"]],
                         [("Local::Get", 103), ("Foo::Foo", 102)])


MAP_HEADERS = {
    "map_model/keyframe.h": """
        #pragma once
        namespace pkslam {
        class KeyFrame {
         public:
          KeyFrame();
          int id() const;
          std::vector<int> matches;
          const int kind = 0;
          static int count;
          const KeyFrame* parent = nullptr;
          KeyFrame* const self = nullptr;
          static constexpr int kMax = 4;
          const std::vector<int>& ref;
          int a = 0, b = 1;
          struct Imu {
            int bias;
          };
          std::map<int, std::pair<int, int>> edges{};

         private:
          int secret_;

         public:
          double weight = 1.0;
        };
        }  // namespace pkslam
        """,
    "map_model/map_point.h": """
        struct MapPoint {
          int position;
         private:
          int hidden_;
        };
        """,
    "map_model/map.h": """
        class Map {
          int private_by_default;
        };
        """,
    # Not a map class: outside map_model/.
    "tracking/frame.h": """
        struct Frame {
          int x;
        };
        """,
}


class FieldTest(unittest.TestCase):
    def test_public_mutable_fields(self):
        with tempfile.TemporaryDirectory() as root:
            for rel, text in MAP_HEADERS.items():
                write(root, rel, text)
            counts = sc.count_tree(root, duplicates=False)
        fields = counts["map_public_mutable_fields_by_class"]
        self.assertEqual(fields["KeyFrame"], ["matches", "parent", "a", "b", "edges", "weight"])
        self.assertEqual(fields["MapPoint"], ["position"])
        self.assertEqual(fields["Map"], [])
        self.assertNotIn("Frame", fields)
        self.assertEqual(counts["map_public_mutable_fields"], 7)


LOCK_HEADER = """
#pragma once
namespace pkslam {

// Requires the exclusive lock.
void A();
// Caller holds the Atlas lock (shared).
void B();
void C();  // Atlas lock held
// Called with no Atlas lock held.
void D();
// Two lines that
// say nothing.

// Computes E. Requires the Atlas
// mutex (shared).
void E();
void F(const MapWriteLock& lock, int x);
void G(std::unique_lock<std::mutex>& lock);
void H(const Atlas& atlas);  // a "lock" in a string is no comment
/* Shared lock. */
void I();

class MapWriteLock {
 public:
  MapWriteLock(MapWriteLock&& other) noexcept = default;
  MapWriteLock& operator=(const MapWriteLock&) = delete;
};

class MapLock {
 public:
  MapLock(const MapReadLock& lock);
};
void RequireMapLock(const MapLock& lock);
void K(const MapLock& lock);

class Queue {
 public:
  int Size() const PKSLAM_REQUIRES(mutex_);
  void Wait(MapReadLock* lock) { (void)lock; }
  void Take() PKSLAM_EXCLUDES(mutex_);

 private:
  Mutex mutex_;
};

}  // namespace pkslam
"""


class LockTest(unittest.TestCase):
    def test_comments_and_signatures(self):
        with tempfile.TemporaryDirectory() as root:
            write(root, "map_model/locks.h", LOCK_HEADER)
            write(root, "map_model/locks.cc", "// Requires the exclusive lock.\nvoid A() {}\n")
            counts = sc.count_tree(root, duplicates=False)
        self.assertEqual([p["line"] for p in counts["lock_comment_places"]], [4, 6, 8, 14, 20])
        self.assertEqual(counts["lock_comments"], 5)
        self.assertEqual([(p["function"], p["by"]) for p in counts["lock_checked_places"]],
                         [("F", "lock parameter MapWriteLock"), ("G", "lock parameter unique_lock"),
                          ("K", "lock parameter MapLock"), ("Size", "PKSLAM_REQUIRES"),
                          ("Wait", "lock parameter MapReadLock")])
        self.assertEqual((counts["lock_checked"], counts["lock_checked_by_parameter"],
                          counts["lock_checked_by_annotation"]), (5, 4, 1))


class HeaderNameTest(unittest.TestCase):
    def test_shared_header_names(self):
        with tempfile.TemporaryDirectory() as root:
            write(root, "core/CMakeLists.txt", "pkslam_library(pkslam_core SOURCES a.cc)\n")
            write(root, "io/CMakeLists.txt",
                  "# pkslam_library(pkslam_old SOURCES old.cc)\n"
                  "pkslam_library(pkslam_io SOURCES b.cc DEPS pkslam_core)\n")
            write(root, "core/ids.h", "int a;\n")
            write(root, "io/ids.h", "int b;\n")
            write(root, "io/only.h", "int c;\n")
            write(root, "io/sub/trajectory.h", "int d;\n")
            write(root, "sim/trajectory.h", "int e;\n")  # no library: not counted
            counts = sc.count_tree(root, duplicates=False)
        self.assertEqual(counts["duplicated_header_names"], 1)
        self.assertEqual(counts["duplicated_header_name_list"],
                         {"ids.h": ["core/ids.h", "io/ids.h"]})


class DuplicatesTest(unittest.TestCase):
    def test_without_the_tool(self):
        with tempfile.TemporaryDirectory() as root:
            write(root, "core/a.cc", "int f() { return 1; }\n")
            counts = sc.count_tree(root, duplicates=False)
            self.assertIsNone(counts["duplicates"])
            self.assertIn("| duplicate pairs (`duplicates`) | n/a |", sc.table([("t", counts)]))
            with mock.patch.object(sc.shutil, "which", return_value=None):
                self.assertIsNone(sc.duplicate_pairs(root, 5))

    def test_reads_the_tools_first_line(self):
        with tempfile.TemporaryDirectory() as root:
            tool = os.path.join(root, "bin", "duplicates")
            write(root, "bin/duplicates",
                  '#!/bin/sh\necho "12 pairs of places (3 files read), each sharing runs"\n'
                  'echo "D1 a.cc:1-9 ~ b.cc:1-9"\necho "incomplete: time: 2 files not read"\n')
            os.chmod(tool, 0o755)
            with mock.patch.object(sc.shutil, "which", return_value=tool):
                found = sc.duplicate_pairs(root, 5)
            self.assertEqual((found["pairs"], found["files"], found["incomplete"]), (12, 3, True))
            self.assertEqual(sc.dup_cell(found), "12*")
            write(root, "bin/duplicates", '#!/bin/sh\necho "no duplicates (4 files read)"\n')
            with mock.patch.object(sc.shutil, "which", return_value=tool):
                self.assertEqual(sc.duplicate_pairs(root, 5)["pairs"], 0)


class StripTest(unittest.TestCase):
    def test_literals_comments_and_directives(self):
        text = ('#define X { \\\n  }\nint a = \'{\'; // {\nconst char* s = R"d(})d";\n'
                "/* { */ int b = 1'000; const char* t = \"\\\"{\";\n")
        code, comments = cpp_model.strip_code(text)
        self.assertEqual(code.count("\n"), text.count("\n"))
        self.assertNotIn("{", code)
        self.assertNotIn("}", code)
        self.assertEqual([(c[0], c[2].strip(), c[3], c[4]) for c in comments],
                         [(3, "{", True, "//"), (5, "{", False, "/*")])


@unittest.skipIf(shutil.which("git") is None, "no git")
class CommitTest(unittest.TestCase):
    def test_before_and_after(self):
        with tempfile.TemporaryDirectory() as root:
            def git(*args):
                subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", "-C", root]
                               + list(args), check=True, capture_output=True)

            git("init", "-q")
            write(root, "core/long.cc", function("Long", 160))
            git("add", "-A")
            git("commit", "-q", "-m", "before")
            write(root, "core/long.cc", function("Half", 80) + function("Other", 80))
            write(root, "core/uncommitted.cc", function("NotYet", 200))
            git("add", "core/long.cc")
            git("commit", "-q", "-m", "after")
            out = io.StringIO()
            json_path = os.path.join(root, "counts.json")
            with contextlib.redirect_stdout(out):
                sc.main(["--before", "HEAD~1", "--after", "HEAD", "--repo", root,
                         "--no-duplicates", "--json", json_path])
            with open(json_path) as f:
                columns = json.load(f)["columns"]
        self.assertTrue(out.getvalue().startswith("| count | HEAD~1 ("))
        self.assertIn("| functions over 150 lines | 1 | 0 |", out.getvalue())
        self.assertEqual([c["counts"]["functions_over_100"] for c in columns], [1, 0])
        self.assertEqual(columns[0]["counts"]["long_functions"][0]["name"], "Long")


if __name__ == "__main__":
    unittest.main()
