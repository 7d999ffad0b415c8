#include "bench/suite.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "bench/peer_import.h"
#include "core/util/error.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

// Parsing context: the file for messages and the directory relative paths resolve against.
struct Context {
  fs::path file;
  fs::path dir;

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& what) const {
    const std::size_t line = node.Mark().is_null() ? 0 : node.Mark().line + 1;
    throw InputError(file, line, what);
  }
  std::size_t Line(const YAML::Node& node) const {
    return node.Mark().is_null() ? 0 : node.Mark().line + 1;
  }
};

void CheckKeys(const Context& c, const YAML::Node& map, const std::string& what,
               const std::set<std::string>& allowed) {
  if (!map.IsMap()) c.Fail(map, what + " must be a mapping");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    if (allowed.count(key) == 0) {
      std::string list;
      for (const auto& a : allowed) {
        if (!list.empty()) list.append(", ");
        list.append(a);
      }
      c.Fail(kv.first, "unknown key '" + key + "' in " + what + " (allowed: " + list + ")");
    }
  }
}

std::string String(const Context& c, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) c.Fail(node, "'" + key + "' must be a string");
  return ExpandEnvironment(node.Scalar(), c.file, c.Line(node));
}

double Number(const Context& c, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) c.Fail(node, "'" + key + "' must be a number");
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    c.Fail(node, "'" + key + "' must be a number, not '" + node.Scalar() + "'");
  }
}

long long Integer(const Context& c, const YAML::Node& node, const std::string& key, long long min) {
  long long v = 0;
  try {
    if (!node.IsScalar()) throw YAML::Exception(node.Mark(), "");
    v = node.as<long long>();
  } catch (const YAML::Exception&) {
    c.Fail(node, "'" + key + "' must be an integer");
  }
  if (v < min) c.Fail(node, fmt::format("'{}' must be >= {} (got {})", key, min, v));
  return v;
}

bool Bool(const Context& c, const YAML::Node& node, const std::string& key) {
  try {
    return node.as<bool>();
  } catch (const YAML::Exception&) {
    c.Fail(node, "'" + key + "' must be true or false");
  }
}

fs::path Path(const Context& c, const YAML::Node& node, const std::string& key) {
  const fs::path p = String(c, node, key);
  if (p.empty()) c.Fail(node, "'" + key + "' is empty");
  return p.is_absolute() ? p : (c.dir / p).lexically_normal();
}

std::vector<std::string> StringList(const Context& c, const YAML::Node& node,
                                    const std::string& key) {
  std::vector<std::string> out;
  if (node.IsScalar()) return {String(c, node, key)};
  if (!node.IsSequence()) c.Fail(node, "'" + key + "' must be a list of strings");
  for (const auto& item : node) out.push_back(String(c, item, key));
  return out;
}

std::map<std::string, double> Params(const Context& c, const YAML::Node& node) {
  if (!node.IsMap()) c.Fail(node, "'params' must be a mapping NAME: number");
  std::map<std::string, double> out;
  for (const auto& kv : node) {
    std::string name = kv.first.as<std::string>();
    if (name.rfind("Keyframe.", 0) == 0) name = name.substr(9);
    out[name] = Number(c, kv.second, "params." + name);
  }
  return out;
}

SimRecipe ParseSim(const Context& c, const YAML::Node& node) {
  CheckKeys(c, node, "sim",
            {"trajectory", "motion", "start", "duration", "scene", "quality", "seed",
             "seed_per_run", "args"});
  SimRecipe r;
  if (node["trajectory"]) {
    r.trajectory = Path(c, node["trajectory"], "trajectory");
    if (!fs::exists(r.trajectory)) {
      c.Fail(node["trajectory"], "trajectory file " + r.trajectory.string() + " does not exist");
    }
  }
  if (node["motion"]) r.motion = String(c, node["motion"], "motion");
  if (r.trajectory.empty() && r.motion.empty()) {
    c.Fail(node, "sim needs 'trajectory' (replay) or 'motion' (easy|medium|difficult)");
  }
  if (!r.trajectory.empty() && !r.motion.empty()) {
    c.Fail(node["motion"], "sim takes 'trajectory' or 'motion', not both");
  }
  if (node["start"]) r.start_s = Number(c, node["start"], "start");
  if (node["duration"]) r.duration_s = Number(c, node["duration"], "duration");
  if (r.start_s < 0 || r.duration_s < 0) c.Fail(node, "sim start and duration must be >= 0");
  if (node["scene"]) r.scene = String(c, node["scene"], "scene");
  if (node["quality"]) r.quality = String(c, node["quality"], "quality");
  if (node["seed"]) r.seed = static_cast<std::uint64_t>(Integer(c, node["seed"], "seed", 0));
  if (node["seed_per_run"]) r.seed_per_run = Bool(c, node["seed_per_run"], "seed_per_run");
  if (node["args"]) r.extra_args = StringList(c, node["args"], "args");
  for (const auto& a : r.extra_args) {
    if (a == "--out" || a == "--seed" || a == "--trajectory") {
      c.Fail(node["args"], "sim args must not contain " + a + " (the harness sets it)");
    }
  }
  return r;
}

DatasetSpec ParseDataset(const Context& c, const YAML::Node& node) {
  CheckKeys(c, node, "a dataset",
            {"name", "path", "sim", "ground_truth", "settings", "sensors", "max_frames"});
  DatasetSpec d;
  if (!node["name"]) c.Fail(node, "dataset without 'name'");
  d.name = String(c, node["name"], "name");
  if (d.name.empty() || d.name.find_first_of("/\\ \t") != std::string::npos) {
    c.Fail(node["name"], "dataset name '" + d.name + "' must be non-empty without '/' or spaces");
  }
  if (node["path"] && node["sim"])
    c.Fail(node, "dataset '" + d.name + "': 'path' or 'sim', not both");
  if (node["path"]) {
    d.path = Path(c, node["path"], "path");
  } else if (node["sim"]) {
    d.sim = ParseSim(c, node["sim"]);
  } else {
    c.Fail(node, "dataset '" + d.name + "' needs 'path' (data on disk) or 'sim' (a recipe)");
  }
  if (node["ground_truth"]) d.ground_truth = Path(c, node["ground_truth"], "ground_truth");
  if (node["settings"]) {
    // A path inside the dataset folder is only known when the run starts (a rendering's cache
    // folder): the executor substitutes it.
    const std::string text = String(c, node["settings"], "settings");
    d.settings = text.find(kDatasetPlaceholder) != std::string::npos
                     ? fs::path(text)
                     : Path(c, node["settings"], "settings");
  }
  if (node["sensors"]) d.sensors = StringList(c, node["sensors"], "sensors");
  if (node["max_frames"]) {
    d.max_frames = static_cast<int>(Integer(c, node["max_frames"], "max_frames", 0));
  }
  return d;
}

SelectorSpec ParseSelector(const Context& c, const YAML::Node& node) {
  SelectorSpec s;
  if (node.IsScalar()) {
    s.name = String(c, node, "selectors");
  } else {
    CheckKeys(c, node, "a selector", {"name", "label", "params", "args"});
    if (!node["name"]) c.Fail(node, "selector without 'name'");
    s.name = String(c, node["name"], "name");
    if (node["label"]) s.label = String(c, node["label"], "label");
    if (node["params"]) s.params = Params(c, node["params"]);
    if (node["args"]) {
      if (!node["args"].IsSequence()) c.Fail(node["args"], "'args' must be a list of strings");
      for (const YAML::Node& a : node["args"]) s.args.push_back(String(c, a, "args"));
    }
  }
  if (s.label.empty()) s.label = s.name;
  if (s.name.empty() || s.label.find_first_of("/\\ \t@") != std::string::npos) {
    c.Fail(node, "selector label '" + s.label + "' must be non-empty without '/', '@' or spaces");
  }
  return s;
}

PeerSpec ParsePeer(const Context& c, const YAML::Node& node) {
  CheckKeys(c, node, "a peer", {"label", "command", "sensors"});
  if (!node["label"] || !node["command"]) c.Fail(node, "a peer needs 'label' and 'command'");
  PeerSpec p;
  p.label = String(c, node["label"], "label");
  if (p.label.empty() || p.label.find_first_of("/\\ \t@") != std::string::npos) {
    c.Fail(node, "peer label '" + p.label + "' must be non-empty without '/', '@' or spaces");
  }
  p.line = c.Line(node);
  p.command = StringList(c, node["command"], "command");
  if (p.command.empty() || p.command.front().empty()) c.Fail(node, "peer command is empty");
  if (node["sensors"]) p.sensors = StringList(c, node["sensors"], "sensors");
  return p;
}

SweepSpec ParseSweep(const Context& c, const YAML::Node& node) {
  CheckKeys(c, node, "a sweep", {"selector", "param", "values", "datasets", "dense"});
  SweepSpec s;
  if (!node["selector"] || !node["param"] || !node["values"]) {
    c.Fail(node, "a sweep needs 'selector', 'param' and 'values'");
  }
  s.selector = String(c, node["selector"], "selector");
  s.param = String(c, node["param"], "param");
  if (s.param.rfind("Keyframe.", 0) == 0) s.param = s.param.substr(9);
  const YAML::Node v = node["values"];
  if (!v.IsSequence() || v.size() == 0) c.Fail(v, "sweep 'values' must be a non-empty list");
  for (const auto& x : v) s.values.push_back(Number(c, x, "values"));
  if (node["datasets"]) s.datasets = StringList(c, node["datasets"], "datasets");
  if (node["dense"]) s.dense = Bool(c, node["dense"], "dense");
  return s;
}

void Validate(const Context& c, const YAML::Node& root, Suite& s) {
  if (s.datasets.empty()) c.Fail(root, "the suite lists no datasets");
  if (s.selectors.empty() && s.peers.empty()) c.Fail(root, "the suite lists no selectors or peers");
  std::set<std::string> names;
  for (const auto& d : s.datasets) {
    if (!names.insert(d.name).second)
      c.Fail(root["datasets"], "dataset name '" + d.name + "' repeats");
    if (d.sensors.empty() && s.sensors.empty()) {
      c.Fail(root, "dataset '" + d.name + "' has no sensors (set 'sensors' in the suite)");
    }
  }
  std::set<std::string> labels;
  for (const auto& sel : s.selectors) {
    if (!labels.insert(sel.label).second) {
      c.Fail(root["selectors"], "selector label '" + sel.label + "' repeats: give 'label'");
    }
  }
  for (const auto& peer : s.peers) {
    if (!labels.insert(peer.label).second) {
      c.Fail(root["peers"], "peer label '" + peer.label + "' repeats a selector or peer label");
    }
  }
  for (const auto& sw : s.sweeps) {
    const bool known = std::any_of(s.selectors.begin(), s.selectors.end(),
                                   [&](const auto& sel) { return sel.label == sw.selector; });
    if (!known) {
      c.Fail(root["sweeps"],
             "sweep selector '" + sw.selector + "' is not one of the suite's selectors");
    }
    for (const auto& d : sw.datasets) {
      if (names.count(d) == 0)
        c.Fail(root["sweeps"], "sweep dataset '" + d + "' is not in the suite");
    }
  }
}

}  // namespace

std::string ExpandEnvironment(const std::string& text, const fs::path& file, std::size_t line) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] != '$' || i + 1 >= text.size() || text[i + 1] != '{') {
      out += text[i++];
      continue;
    }
    const std::size_t close = text.find('}', i);
    if (close == std::string::npos)
      throw InputError(file, line, "unterminated ${ in '" + text + "'");
    const std::string inner = text.substr(i + 2, close - i - 2);
    const std::size_t dash = inner.find(":-");
    const std::string var = inner.substr(0, dash);
    const char* value = std::getenv(var.c_str());
    if (value != nullptr && *value != '\0') {
      out += value;
    } else if (dash != std::string::npos) {
      out += inner.substr(dash + 2);
    } else {
      throw InputError(file, line, "environment variable " + var + " is not set");
    }
    i = close + 1;
  }
  return out;
}

Suite ParseSuite(const std::string& text, const fs::path& file) {
  // Absolute, so commands work from any directory (emitted jobs) and cache keys are stable.
  Context c{file, fs::absolute(file.parent_path().empty() ? fs::path(".") : file.parent_path())
                      .lexically_normal()};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(file, e.mark.line + 1, "YAML syntax: " + e.msg);
  }
  if (!root || root.IsNull()) throw InputError(file, "empty suite");
  CheckKeys(c, root, "the suite",
            {"name", "runs", "seed", "deterministic", "trace", "dense", "baseline", "alignment",
             "timeout_s", "rpe_delta_m", "sensors", "selectors", "peers", "params", "sweeps",
             "datasets"});
  Suite s;
  s.file = file;
  s.name = root["name"] ? String(c, root["name"], "name") : file.stem().string();
  if (root["runs"]) {
    // Every run is a result row and a folder: a typo such as 100000000 used to grow memory
    // until std::bad_alloc instead of being named.
    const long long runs = Integer(c, root["runs"], "runs", 1);
    if (runs > 1000) c.Fail(root["runs"], fmt::format("'runs' must be <= 1000 (got {})", runs));
    s.runs = static_cast<int>(runs);
  }
  if (root["seed"]) s.seed = static_cast<std::uint64_t>(Integer(c, root["seed"], "seed", 0));
  if (root["deterministic"]) s.deterministic = Bool(c, root["deterministic"], "deterministic");
  if (root["trace"]) s.trace = Bool(c, root["trace"], "trace");
  if (root["dense"]) s.dense = Bool(c, root["dense"], "dense");
  if (root["baseline"]) s.baseline = String(c, root["baseline"], "baseline");
  if (root["alignment"]) {
    s.alignment = String(c, root["alignment"], "alignment");
    if (s.alignment != "se3" && s.alignment != "sim3" && s.alignment != "auto") {
      c.Fail(root["alignment"], "'alignment' must be se3, sim3 or auto");
    }
  }
  if (root["timeout_s"]) s.timeout_s = Number(c, root["timeout_s"], "timeout_s");
  if (root["rpe_delta_m"]) s.rpe_delta_m = Number(c, root["rpe_delta_m"], "rpe_delta_m");
  if (s.timeout_s <= 0) c.Fail(root["timeout_s"], "'timeout_s' must be > 0");
  if (s.rpe_delta_m <= 0) c.Fail(root["rpe_delta_m"], "'rpe_delta_m' must be > 0");
  if (root["sensors"]) s.sensors = StringList(c, root["sensors"], "sensors");
  if (root["selectors"]) {
    const YAML::Node sel = root["selectors"];
    if (!sel.IsSequence()) c.Fail(sel, "'selectors' must be a list");
    for (const auto& n : sel) s.selectors.push_back(ParseSelector(c, n));
  }
  if (root["peers"]) {
    const YAML::Node peers = root["peers"];
    if (!peers.IsSequence()) c.Fail(peers, "'peers' must be a list");
    for (const auto& n : peers) s.peers.push_back(ParsePeer(c, n));
  }
  if (root["params"]) s.params = Params(c, root["params"]);
  if (root["sweeps"]) {
    const YAML::Node sw = root["sweeps"];
    if (!sw.IsSequence()) c.Fail(sw, "'sweeps' must be a list");
    for (const auto& n : sw) s.sweeps.push_back(ParseSweep(c, n));
  }
  if (root["datasets"]) {
    const YAML::Node ds = root["datasets"];
    if (!ds.IsSequence()) c.Fail(ds, "'datasets' must be a list");
    for (const auto& n : ds) s.datasets.push_back(ParseDataset(c, n));
  }
  Validate(c, root, s);
  return s;
}

namespace {

bool Executable(const fs::path& file) {
  return fs::is_regular_file(file) && access(file.c_str(), X_OK) == 0;
}

// A bare program name as posix_spawnp finds it: the first executable of that name on PATH.
bool OnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (Executable(fs::path(dir.empty() ? "." : dir) / name)) return true;
  }
  return false;
}

}  // namespace

void CheckPeerCommands(const Suite& suite, const std::set<std::string>& peers) {
  const fs::path suite_dir = fs::absolute(suite.file).parent_path();
  for (const PeerSpec& p : suite.peers) {
    if (peers.count(p.label) == 0) continue;
    auto fail = [&](const std::string& what) {
      throw InputError(suite.file, p.line, "peer '" + p.label + "': " + what);
    };
    // The command as the executor will fill it in, the run's own placeholders left as they are.
    const std::vector<std::string> argv =
        PeerArguments(p.command, "{dataset}", "{sensor}", "{out}", 0, suite_dir);
    const std::string& program = argv.front();
    const bool found =
        program.find('/') == std::string::npos ? OnPath(program) : Executable(program);
    if (!found) fail("cannot run '" + program + "' (no such executable file)");
    for (std::size_t i = 1; i < argv.size(); ++i) {
      const bool beside_suite = p.command[i].find("{suite_dir}") != std::string::npos;
      if (beside_suite && !fs::exists(argv[i])) fail("'" + argv[i] + "' does not exist");
    }
  }
}

Suite ReadSuite(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "cannot read the suite file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseSuite(buffer.str(), file);
}

}  // namespace pkslam::bench
