"""The layering check fails on an include of a higher layer and on a dependency cycle."""

import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_includes.py")


def make_repo(root, low_includes, low_deps="", extra=None):
    files = dict(extra or {})
    files.update({
        "low/CMakeLists.txt": f"pkslam_library(pkslam_low\n  SOURCES a.cc\n  DEPS {low_deps}\n"
                              "  TESTS a_test.cc\n  TEST_DEPS pkslam_high\n)\n",
        "low/a.h": "#pragma once\n",
        "low/a.cc": f'#include "low/a.h"\n{low_includes}',
        "low/a_test.cc": '#include "high/b.h"\n',  # tests may use their TEST_DEPS
        "high/CMakeLists.txt": "pkslam_library(pkslam_high\n  SOURCES b.cc\n  DEPS pkslam_low\n)\n",
        "high/b.h": '#pragma once\n#include "low/a.h"\n',
        "high/b.cc": '#include "high/b.h"\n',
    })
    for path, text in files.items():
        os.makedirs(os.path.join(root, os.path.dirname(path)), exist_ok=True)
        with open(os.path.join(root, path), "w") as f:
            f.write(text)


def check(root):
    return subprocess.run([sys.executable, SCRIPT, root], capture_output=True, text=True)


class LayeringTest(unittest.TestCase):
    def test_clean_repo_passes(self):
        with tempfile.TemporaryDirectory() as d:
            make_repo(d, "")
            r = check(d)
            self.assertEqual(r.returncode, 0, r.stdout)

    def expect_failure(self, message, low_includes="", **repo):
        with tempfile.TemporaryDirectory() as d:
            make_repo(d, low_includes, **repo)
            r = check(d)
            self.assertEqual(r.returncode, 1)
            self.assertIn(message, r.stdout)

    def test_include_of_a_higher_layer_fails_naming_file_and_line(self):
        self.expect_failure("low/a.cc:2: includes high/b.h of pkslam_high", '#include "high/b.h"\n')

    def test_cycle_fails(self):
        self.expect_failure("dependency cycle", low_deps="pkslam_high")

    def test_a_header_name_in_two_libraries_fails_naming_both(self):
        self.expect_failure("header name a.h is used by 2 libraries: high/a.h, low/a.h",
                            extra={"high/a.h": "#pragma once\n"})

    def test_one_library_may_use_a_name_in_two_folders_of_its_own(self):
        with tempfile.TemporaryDirectory() as d:
            make_repo(d, "", extra={"low/sub/a.h": "#pragma once\n"})
            r = check(d)
            self.assertEqual(r.returncode, 0, r.stdout)


if __name__ == "__main__":
    unittest.main()
