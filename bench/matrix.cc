#include "bench/matrix.h"

#include <algorithm>
#include <charconv>
#include <map>
#include <set>
#include <utility>

#include "core/util/error.h"

namespace pkslam::bench {
namespace {

struct Config {
  std::string label;
  std::string selector;
  std::map<std::string, double> params;
  std::string sweep_param;
  double sweep_value = 0.0;
  bool dense = false;
  std::vector<std::string> peer_command;
  std::vector<std::string> peer_sensors;  // empty: all
  std::vector<std::string> run_args;
};

// The configurations run on `dataset`: the suite's selectors, then the sweep points.
std::vector<Config> Configurations(const Suite& suite, const std::string& dataset) {
  std::vector<Config> out;
  for (const auto& sel : suite.selectors) {
    Config c{sel.label, sel.name, suite.params, "", 0.0, suite.dense, {}, {}, sel.args};
    for (const auto& [k, v] : sel.params) c.params[k] = v;
    out.push_back(c);
  }
  for (const auto& sw : suite.sweeps) {
    if (!sw.datasets.empty() &&
        std::find(sw.datasets.begin(), sw.datasets.end(), dataset) == sw.datasets.end()) {
      continue;
    }
    const SelectorSpec* base = nullptr;
    for (const auto& sel : suite.selectors) {
      if (sel.label == sw.selector) base = &sel;
    }
    PKSLAM_CHECK(base != nullptr, "sweep selector {} not in the suite", sw.selector);
    for (double v : sw.values) {
      Config c{base->label + "@" + sw.param + "=" + FormatNumber(v),
               base->name,
               suite.params,
               sw.param,
               v,
               suite.dense || sw.dense,
               {},
               {},
               base->args};
      for (const auto& [k, x] : base->params) c.params[k] = x;
      c.params[sw.param] = v;
      out.push_back(c);
    }
  }
  for (const auto& peer : suite.peers) {
    Config c;
    c.label = peer.label;
    c.selector = "peer";
    c.peer_command = peer.command;
    c.peer_sensors = peer.sensors;
    out.push_back(c);
  }
  return out;
}

}  // namespace

std::string FormatNumber(double value) {
  char buffer[64];
  const auto r = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, r.ptr);
}

std::string FormatParams(const std::map<std::string, double>& params) {
  std::string out;
  for (const auto& [k, v] : params) {
    if (!out.empty()) out.push_back(';');
    out.append(k).append("=").append(FormatNumber(v));
  }
  return out;
}

std::vector<RunSpec> ExpandSuite(const Suite& suite) {
  std::vector<RunSpec> out;
  for (const auto& d : suite.datasets) {
    const std::vector<Config> configs = Configurations(suite, d.name);
    const auto& sensors = d.sensors.empty() ? suite.sensors : d.sensors;
    for (const auto& sensor : sensors) {
      for (const auto& c : configs) {
        if (!c.peer_sensors.empty() && std::find(c.peer_sensors.begin(), c.peer_sensors.end(),
                                                 sensor) == c.peer_sensors.end()) {
          continue;
        }
        for (int k = 0; k < suite.runs; ++k) {
          RunSpec r;
          r.index = static_cast<int>(out.size());
          r.dataset = d.name;
          r.sensor = sensor;
          r.config = c.label;
          r.selector = c.selector;
          r.params = c.params;
          r.sweep_param = c.sweep_param;
          r.sweep_value = c.sweep_value;
          r.dense = c.dense;
          r.peer_command = c.peer_command;
          r.run_args = c.run_args;
          r.run = k;
          r.seed = suite.seed + static_cast<std::uint64_t>(k);
          if (d.sim) {
            r.sim = *d.sim;
            if (d.sim->seed_per_run) r.sim->seed = d.sim->seed + static_cast<std::uint64_t>(k);
          }
          r.id = d.name + "/" + sensor + "/" + c.label + "/seed" + std::to_string(r.seed);
          out.push_back(std::move(r));
        }
      }
    }
  }
  return out;
}

const DatasetSpec& DatasetOf(const Suite& suite, const RunSpec& run) {
  for (const auto& d : suite.datasets) {
    if (d.name == run.dataset) return d;
  }
  throw Error("run " + run.id + ": dataset not in the suite");
}

std::vector<RunSpec> SelectSensors(const std::vector<RunSpec>& runs,
                                   const std::vector<std::string>& sensors) {
  if (sensors.empty()) return runs;
  std::vector<RunSpec> out;
  for (const auto& sensor : sensors) {
    const bool known =
        std::any_of(runs.begin(), runs.end(), [&](const RunSpec& r) { return r.sensor == sensor; });
    if (!known) throw OptionError("--sensor '" + sensor + "': the suite runs no such sensor");
  }
  for (const auto& r : runs) {
    if (std::find(sensors.begin(), sensors.end(), r.sensor) != sensors.end()) out.push_back(r);
  }
  return out;
}

std::vector<RunSpec> SelectConfigs(const std::vector<RunSpec>& runs,
                                   const std::vector<std::string>& configs) {
  if (configs.empty()) return runs;
  std::set<std::string> labels;
  for (const auto& r : runs) labels.insert(r.config);
  const auto selects = [&](const std::string& name, const RunSpec& r) {
    if (r.config == name) return true;
    if (labels.count(name) > 0) return false;  // a configuration's own label wins over the groups
    if (name == "peers") return !r.peer_command.empty();
    if (name == "pkslam") return r.peer_command.empty();
    return false;
  };
  for (const auto& name : configs) {
    const bool any =
        std::any_of(runs.begin(), runs.end(), [&](const RunSpec& r) { return selects(name, r); });
    if (!any) {
      throw OptionError("--config '" + name +
                        "': no run of the suite has this configuration (a label, 'peers' or "
                        "'pkslam')");
    }
  }
  std::vector<RunSpec> out;
  for (const auto& r : runs) {
    if (std::any_of(configs.begin(), configs.end(),
                    [&](const std::string& name) { return selects(name, r); })) {
      out.push_back(r);
    }
  }
  return out;
}

std::vector<const RunSpec*> RenderingOrder(
    std::vector<const RunSpec*> runs,
    const std::function<std::optional<std::string>(const RunSpec&)>& rendering_of) {
  struct Rank {
    int lowest_run;
    std::size_t first;
  };
  std::map<std::string, Rank> ranks;
  std::vector<std::optional<std::string>> keys;
  keys.reserve(runs.size());
  for (const RunSpec* r : runs) {
    keys.push_back(rendering_of(*r));
    if (!keys.back()) continue;
    const auto [it, added] = ranks.try_emplace(*keys.back(), Rank{r->run, ranks.size()});
    if (!added) it->second.lowest_run = std::min(it->second.lowest_run, r->run);
  }
  std::vector<std::size_t> order(runs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto rank = [&](std::size_t i) {
    if (!keys[i]) return std::pair<int, std::size_t>(-1, 0);
    const Rank& k = ranks.at(*keys[i]);
    return std::pair<int, std::size_t>(k.lowest_run, k.first);
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return rank(a) < rank(b); });
  std::vector<const RunSpec*> out;
  out.reserve(runs.size());
  for (const std::size_t i : order) out.push_back(runs[i]);
  return out;
}

}  // namespace pkslam::bench
