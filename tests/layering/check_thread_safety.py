#!/usr/bin/python3
"""Clang's thread-safety analysis over the sources that use core/util/annotated_mutex.h: each is
compiled with clang++ -fsyntax-only -Wthread-safety (as errors), with the flags CMake recorded
for it in compile_commands.json. GCC builds pkslam and ignores the annotations; this is where
they are checked. Prints Clang's diagnostics and exits 1 on any; exits 0 with a note when
clang++ is missing (the analysis is an extra check, not a build requirement).

  /usr/bin/python3 tests/layering/check_thread_safety.py BUILD_DIR [REPO]
      (CTest: layering.thread_safety)
  /usr/bin/python3 tests/layering/check_thread_safety.py --self-test [REPO]
      (CTest: layering.thread_safety_self_test: a guarded read without the lock is found, the
      same read under a MutexLock and a wait loop on a ConditionVariable are not)
"""

import concurrent.futures
import json
import os
import shlex
import shutil
import subprocess
import sys

HEADER = "core/util/annotated_mutex.h"
# Flags of the GCC command line that Clang does not take or that would turn other warnings on.
DROP = {"-Wall", "-Wextra", "-Werror"}


def users(repo):
    """Sources (.cc) that include the annotated header, directly or through a header that does."""
    headers = {HEADER}
    files = []
    for root, dirs, names in os.walk(repo):
        dirs[:] = [d for d in dirs if not d.startswith("build") and d not in (".git", "third_party")]
        for n in names:
            if n.endswith((".h", ".cc")):
                files.append(os.path.relpath(os.path.join(root, n), repo))
    text = {f: open(os.path.join(repo, f), errors="replace").read() for f in files}
    changed = True
    while changed:  # headers including annotated headers are annotated users too
        changed = False
        for f in files:
            if f.endswith(".h") and f not in headers and any(f'#include "{h}"' in text[f]
                                                            for h in headers):
                headers.add(f)
                changed = True
    return sorted(f for f in files if f.endswith(".cc") and any(f'#include "{h}"' in text[f]
                                                                 for h in headers))


def unity_members(path):
    """The repository-relative sources a generated batch file includes."""
    members = []
    for line in open(path):
        if line.startswith('#include "'):
            members.append(line.split('"')[1])
    return members


def clang_command(entry, source):
    args = shlex.split(entry["command"]) if "command" in entry else list(entry["arguments"])
    out, skip = ["clang++"], False
    for a in args[1:]:
        if skip:
            skip = False
            continue
        if a in ("-o", "-c"):
            skip = True
            continue
        if a in DROP or a == source:
            continue
        out.append(a)
    return out + ["-fsyntax-only", "-Wthread-safety", "-Werror=thread-safety", source]


SNIPPET = """
#include "core/util/annotated_mutex.h"
#include <deque>
class Queue {
 public:
  void Push(int v) { pkslam::MutexLock lock(mutex_); items_.push_back(v); ready_.notify_all(); }
  int Pop() {
    pkslam::MutexLock lock(mutex_);
    while (items_.empty()) ready_.wait(lock);
    const int v = items_.front();
    items_.pop_front();
    return v;
  }
  int Size() const { %s return static_cast<int>(items_.size()); }
 private:
  mutable pkslam::Mutex mutex_;
  pkslam::ConditionVariable ready_;
  std::deque<int> items_ PKSLAM_GUARDED_BY(mutex_);
};
"""


def self_test(repo):
    if shutil.which("clang++") is None:
        print("clang++ not found: self-test skipped")
        return 0
    results = {}
    for name, lock in (("locked", "pkslam::MutexLock lock(mutex_);"), ("unlocked", "")):
        cmd = ["clang++", "-std=c++20", "-I", repo, "-fsyntax-only", "-Wthread-safety",
               "-Werror=thread-safety", "-x", "c++", "-"]
        r = subprocess.run(cmd, input=SNIPPET % lock, capture_output=True, text=True)
        results[name] = (r.returncode, r.stderr)
    ok = results["locked"][0] == 0 and results["unlocked"][0] != 0 and \
        "requires holding mutex" in results["unlocked"][1]
    if not ok:
        print("self-test failed:", results)
        return 1
    print("self-test passed: the unlocked read is reported, the locked one is not")
    return 0


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "--self-test":
        repo = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__),
                                                                   "..", "..")
        return self_test(os.path.realpath(repo))
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    build = sys.argv[1]
    repo = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "..")
    repo = os.path.realpath(repo)
    if shutil.which("clang++") is None:
        print("clang++ not found: thread-safety analysis skipped")
        return 0
    db_path = os.path.join(build, "compile_commands.json")
    if not os.path.exists(db_path):
        print(f"{db_path}: missing (configure with CMAKE_EXPORT_COMPILE_COMMANDS=ON)")
        return 1
    db = {os.path.realpath(e["file"]): e for e in json.load(open(db_path))}
    wanted = users(repo)
    jobs = []
    for rel in wanted:
        path = os.path.join(repo, rel)
        if path in db:
            jobs.append((rel, db[path]))
    # Test and benchmark files are compiled in batches (cmake/PkslamHelpers.cmake,
    # pkslam_unity_sources): a batch that includes a user is analysed whole, its files at once.
    for path, entry in db.items():
        if os.sep + "unity" + os.sep not in path:
            continue
        included = unity_members(path)
        if any(rel in wanted for rel in included):
            jobs.append((f"{os.path.relpath(path, build)} ({', '.join(included)})", entry))
    if not jobs:
        print("no source uses", HEADER)
        return 1

    def run(job):
        rel, entry = job
        cmd = clang_command(entry, os.path.realpath(os.path.join(entry["directory"],
                                                                  entry["file"])))
        r = subprocess.run(cmd, cwd=entry["directory"], capture_output=True, text=True)
        return rel, r.returncode, r.stderr

    failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        for rel, code, err in pool.map(run, jobs):
            if code != 0:
                failed += 1
                print(f"{rel}: thread-safety analysis failed\n{err}")
    print(f"{len(jobs)} sources analysed, {failed} with findings")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
