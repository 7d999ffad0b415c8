"""The architecture check passes a picture that matches the CMake graph and catches each rule's
violation: a library without a node or a node without a library (1), an arrow that is no direct
link (2), a link no path of arrows shows (3)."""

import os
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True
import check_architecture  # noqa: E402

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_architecture.py")

# A small repository: core <- io <- evaluation <- bench (evaluation also links core directly),
# map_model with its test-support library, and the executable pkslam linking bench and map_model.
CMAKE = {
    "core/CMakeLists.txt": "pkslam_library(pkslam_core\n  SOURCES a.cc\n"
                           "  DEPS Eigen3::Eigen pkslam_opencv  # wrappers are not drawn\n)\n",
    "io/CMakeLists.txt": "pkslam_library(pkslam_io\n  SOURCES b.cc\n  DEPS pkslam_core\n)\n",
    "evaluation/CMakeLists.txt": "pkslam_library(pkslam_evaluation\n  SOURCES c.cc\n"
                                 "  DEPS pkslam_io pkslam_core\n  TESTS c_test.cc\n"
                                 "  TEST_DEPS pkslam_map_model\n)\n",
    "bench/CMakeLists.txt": "pkslam_library(pkslam_bench\n  SOURCES d.cc\n"
                                       "  DEPS pkslam_evaluation\n)\n",
    "map_model/CMakeLists.txt": "pkslam_library(pkslam_map_model\n  SOURCES e.cc\n"
                                "  DEPS pkslam_core\n)\n"
                                "add_library(pkslam_map_model_testing STATIC testing/s.cc)\n"
                                "target_link_libraries(pkslam_map_model_testing PUBLIC "
                                "pkslam_map_model)\n",
    "apps/CMakeLists.txt": "add_executable(pkslam\n  main.cc\n)\n"
                           "target_link_libraries(pkslam PRIVATE pkslam_bench CLI11::CLI11 "
                           "pkslam_options)\n"
                           "target_link_libraries(pkslam PRIVATE pkslam_map_model)\n",
}

# The matching picture; evaluation's direct link to core is implied through io.
PICTURE = [
    "  core[core: util, cameras]",
    "  io[io: datasets, settings] --> core",
    "  evaluation[evaluation: ATE/RPE] --> io",
    "  %% a comment",
    "  bench[bench] --> evaluation",
    "  map_model --> core",
    "  apps[apps: pkslam] --> bench & map_model",
]


def make_repo(root, picture=None, extra=None, drop=()):
    files = dict(CMAKE)
    files.update(extra or {})
    lines = PICTURE if picture is None else picture
    files["docs/architecture.md"] = ("# Architecture\n\n```mermaid\nflowchart BT\n"
                                     + "\n".join(lines) + "\n```\n\nText.\n")
    for path, text in files.items():
        if path in drop:
            continue
        os.makedirs(os.path.join(root, os.path.dirname(path)), exist_ok=True)
        with open(os.path.join(root, path), "w") as f:
            f.write(text)


def without(line):
    return [l for l in PICTURE if l != line]


class ArchitectureCheckTest(unittest.TestCase):
    def run_check(self, **repo):
        with tempfile.TemporaryDirectory() as d:
            make_repo(d, **repo)
            return subprocess.run([sys.executable, SCRIPT, d], capture_output=True, text=True)

    def expect_failure(self, message, **repo):
        r = self.run_check(**repo)
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn(message, r.stdout)
        return r

    def test_matching_picture_passes_with_one_summary_line(self):
        r = self.run_check()
        self.assertEqual(r.returncode, 0, r.stdout)
        self.assertEqual(r.stdout.count("\n"), 1, r.stdout)
        self.assertIn("matches the CMake graph (6 targets", r.stdout)

    # Rule 1
    def test_library_without_node_fails(self):
        self.expect_failure("pkslam_map_model (map_model/CMakeLists.txt) has no node",
                            picture=without("  map_model --> core")[:-1]
                            + ["  apps[apps: pkslam] --> bench"])

    def test_executable_without_node_fails(self):
        self.expect_failure("pkslam (apps/CMakeLists.txt) has no node",
                            picture=without("  apps[apps: pkslam] --> bench & map_model"))

    def test_node_without_library_fails(self):
        self.expect_failure("docs/architecture.md:12: node ghost is no target of the library "
                            "graph (pkslam_ghost)", picture=PICTURE + ["  ghost --> core"])

    def test_apps_node_needs_the_executable(self):
        self.expect_failure("node apps is no target of the library graph (pkslam)",
                            drop=("apps/CMakeLists.txt",))

    # Rule 2
    def test_arrow_of_a_transitive_link_fails(self):
        self.expect_failure("docs/architecture.md:12: arrow bench --> io, but pkslam_bench does "
                            "not link pkslam_io directly", picture=PICTURE + ["  bench --> io"])

    def test_reversed_arrow_fails(self):
        self.expect_failure("arrow core --> io, but pkslam_core does not link pkslam_io",
                            picture=PICTURE + ["  core --> io"])

    # Rule 3
    def test_link_without_path_fails(self):
        self.expect_failure("pkslam_io links pkslam_core (io/CMakeLists.txt), but "
                            "docs/architecture.md has no path of arrows from io to core",
                            picture=without("  io[io: datasets, settings] --> core")
                            + ["  io[io: datasets, settings]"])

    def test_link_of_the_executable_without_path_fails(self):
        self.expect_failure("pkslam links pkslam_map_model (apps/CMakeLists.txt), but "
                            "docs/architecture.md has no path of arrows from apps to map_model",
                            picture=without("  apps[apps: pkslam] --> bench & map_model")
                            + ["  apps[apps: pkslam] --> bench"])

    def test_link_added_by_target_link_libraries_counts(self):
        io = (CMAKE["io/CMakeLists.txt"]
              + "target_link_libraries(pkslam_io PRIVATE pkslam_map_model)\n")
        self.expect_failure("pkslam_io links pkslam_map_model",
                            extra={"io/CMakeLists.txt": io})

    # The picture itself
    def test_unreadable_line_fails(self):
        self.expect_failure("docs/architecture.md:12: cannot read `core -.-> io`",
                            picture=PICTURE + ["  core -.-> io"])

    def test_missing_picture_fails(self):
        with tempfile.TemporaryDirectory() as d:
            make_repo(d)
            with open(os.path.join(d, "docs/architecture.md"), "w") as f:
                f.write("# Architecture\n\nNo picture.\n")
            r = subprocess.run([sys.executable, SCRIPT, d], capture_output=True, text=True)
            self.assertEqual(r.returncode, 1)
            self.assertEqual(r.stdout, "docs/architecture.md: no ```mermaid flowchart block\n")


class ParseTest(unittest.TestCase):
    def test_statement_with_labels_chains_and_ampersands(self):
        self.assertEqual(check_architecture.parse_statement(
            "  a[a: x, y (z)] --> b & c{c} --> d([d]);"), [["a"], ["b", "c"], ["d"]])

    def test_labelled_arrow(self):
        self.assertEqual(check_architecture.parse_statement("a -->|links| b"), [["a"], ["b"]])

    def test_other_arrows_are_not_read(self):
        self.assertIsNone(check_architecture.parse_statement("a --- b"))

    def test_node_targets(self):
        self.assertEqual(check_architecture.target_of("map_model"), "pkslam_map_model")
        self.assertEqual(check_architecture.target_of("apps"), "pkslam")


if __name__ == "__main__":
    unittest.main()
