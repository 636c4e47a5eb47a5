// HardwareBinding: adapters chosen by a configuration string, cycled after the controllers; the database
// shows the measured state, and the controller holds while an adapter does not deliver.
#include "vsd/robotics/hardware_binding.hpp"

#include <charconv>
#include <cstdlib>

#include "vsd/core/error.hpp"
#include "vsd/robotics/fieldbus_adapter.hpp"
#include "vsd/robotics/udp_adapter.hpp"

namespace vsd::robotics {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\n')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= s.size(); ++i)
    if (i == s.size() || s[i] == sep) {
      out.push_back(s.substr(start, i - start));
      start = i + 1;
    }
  return out;
}

bool parse_is_sim(std::string_view config) {
  const std::string_view t = trim(config);
  return t.empty() || t == "sim";
}

double number(const AdapterConfig& c, const std::string& key, double fallback) {
  auto it = c.options.find(key);
  if (it == c.options.end()) return fallback;
  const std::string& v = it->second;
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size())
    throw vsd::Error(c.kind + " adapter: '" + key + "=" + v + "' is not a number");
  return d;
}

}  // namespace

std::vector<AdapterConfig> parse_hardware_config(std::string_view config) {
  std::vector<AdapterConfig> out;
  const std::string_view all = trim(config);
  if (all.empty() || all == "sim") return out;
  for (std::string_view raw : split(all, ';')) {
    const std::string_view item = trim(raw);
    if (item.empty()) continue;
    const std::string where = "hardware config item '" + std::string(item) + "'";
    AdapterConfig c;
    std::string_view rest = item;
    const std::size_t q = rest.find('?');
    std::string_view query = q == std::string_view::npos ? std::string_view{} : rest.substr(q + 1);
    if (q != std::string_view::npos) rest = rest.substr(0, q);
    const std::size_t scheme = rest.find("://");
    c.kind = std::string(scheme == std::string_view::npos ? rest : rest.substr(0, scheme));
    if (scheme != std::string_view::npos) c.address = std::string(rest.substr(scheme + 3));
    if (c.kind.empty()) throw vsd::Error(where + ": no adapter kind (udp or fieldbus)");
    if (c.kind != "udp" && c.kind != "fieldbus")
      throw vsd::Error(where + ": unknown adapter kind '" + c.kind + "' (udp or fieldbus)");
    if (!query.empty())
      for (std::string_view kv : split(query, '&')) {
        const std::size_t eq = kv.find('=');
        if (eq == std::string_view::npos || eq == 0)
          throw vsd::Error(where + ": '" + std::string(kv) + "' is not KEY=VALUE");
        const std::string key(kv.substr(0, eq));
        const std::string_view value = kv.substr(eq + 1);
        if (key == "joints") {
          for (std::string_view j : split(value, ','))
            if (!trim(j).empty()) c.joints.emplace_back(trim(j));
        } else {
          c.options[key] = std::string(value);
        }
      }
    out.push_back(std::move(c));
  }
  return out;
}

std::unique_ptr<HardwareAdapter> make_adapter(const AdapterConfig& c, int dof) {
  auto check_keys = [&c](std::initializer_list<std::string_view> known) {
    for (const auto& [k, v] : c.options) {
      bool ok = false;
      for (std::string_view n : known) ok |= k == n;
      if (!ok) throw vsd::Error(c.kind + " adapter: unknown key '" + k + "'");
    }
  };
  if (c.kind == "udp") {
    check_keys({"timeout", "max_missed"});
    UdpOptions o;
    o.dof = dof;
    const std::size_t colon = c.address.rfind(':');
    if (colon == std::string::npos || colon == 0)
      throw vsd::Error("udp adapter: address '" + c.address + "' is not HOST:PORT");
    o.host = c.address.substr(0, colon);
    unsigned port = 0;
    const std::string p = c.address.substr(colon + 1);
    const auto r = std::from_chars(p.data(), p.data() + p.size(), port);
    if (r.ec != std::errc() || r.ptr != p.data() + p.size() || port == 0 || port > 65535)
      throw vsd::Error("udp adapter: '" + p + "' is not a port number (1 to 65535)");
    o.port = static_cast<std::uint16_t>(port);
    o.reply_timeout = number(c, "timeout", o.reply_timeout);
    o.max_missed = static_cast<int>(number(c, "max_missed", o.max_missed));
    return std::make_unique<UdpAdapter>(o);
  }
  if (c.kind == "fieldbus") {
    check_keys({"velocity", "lower", "upper", "following_error", "counts"});
    if (dof != 1)
      throw vsd::Error("fieldbus adapter: drives one axis, " + std::to_string(dof) + " joints were bound");
    FieldbusOptions o;
    o.drive.max_velocity = number(c, "velocity", o.drive.max_velocity);
    o.drive.lower = number(c, "lower", o.drive.lower);
    o.drive.upper = number(c, "upper", o.drive.upper);
    o.drive.following_error = number(c, "following_error", o.drive.following_error);
    o.drive.counts_per_unit = number(c, "counts", o.drive.counts_per_unit);
    return std::make_unique<FieldbusAxisAdapter>(o);
  }
  throw vsd::Error("unknown adapter kind '" + c.kind + "' (udp or fieldbus)");
}

// ---- HardwareBinding ------------------------------------------------------------------------------------

HardwareBinding::~HardwareBinding() = default;

KinematicTree* HardwareBinding::tree() const noexcept {
  NamedModelInstance* o = owner();
  return o != nullptr ? o->find_extension<KinematicTree>() : nullptr;
}

bool HardwareBinding::active() const noexcept { return !parse_is_sim(config()); }

void HardwareBinding::command(std::span<const double> q, std::span<const double> qd) {
  if (!qd.empty() && qd.size() != q.size())
    throw vsd::Error("HardwareBinding '" + name() + "': " + std::to_string(qd.size()) + " velocities for " +
                     std::to_string(q.size()) + " positions");
  command_q_.assign(q.begin(), q.end());
  command_qd_.assign(qd.begin(), qd.end());
  if (command_qd_.empty()) command_qd_.assign(q.size(), 0.0);
  commanded_ = true;
}

void HardwareBinding::set_fault_state(std::string why) {
  if (status() != BindingStatus::Fault) set_fault_count(fault_count() + 1);
  set_status(BindingStatus::Fault);
  if (fault() != why) set_fault(std::move(why));
}

void HardwareBinding::disconnect() {
  for (Bound& b : bound_) b.adapter->disconnect();
  bound_.clear();
  built_ = false;
}

void HardwareBinding::reset_faults() {
  for (Bound& b : bound_) b.adapter->reset_fault();
}

void HardwareBinding::configure() {
  disconnect();
  built_ = true;
  built_config_ = config();
  holding_ = true;
  if (!active()) {
    set_status(BindingStatus::Simulation);
    set_fault("");
    return;
  }
  KinematicTree* t = tree();
  if (t == nullptr) throw vsd::Error("no KinematicTree on the binding's node");
  const Model& m = t->model();
  std::vector<bool> taken(static_cast<std::size_t>(m.dof()), false);
  for (const AdapterConfig& c : parse_hardware_config(config())) {
    Bound b;
    if (c.joints.empty()) {
      for (int i = 0; i < m.dof(); ++i)
        if (!taken[static_cast<std::size_t>(i)]) b.layout.push_back(i);
    } else {
      for (const std::string& j : c.joints) {
        int found = -1;
        for (int i = 0; i < m.dof(); ++i)
          if (m.layout()[static_cast<std::size_t>(i)].name == j) found = i;
        if (found < 0) throw vsd::Error(c.kind + " adapter: no joint '" + j + "' in the tree");
        b.layout.push_back(found);
      }
    }
    if (b.layout.empty()) throw vsd::Error(c.kind + " adapter: no joints left to bind");
    for (int i : b.layout) {
      if (taken[static_cast<std::size_t>(i)])
        throw vsd::Error(c.kind + " adapter: joint '" + m.layout()[static_cast<std::size_t>(i)].name +
                         "' is bound twice");
      taken[static_cast<std::size_t>(i)] = true;
    }
    b.adapter = make_adapter(c, static_cast<int>(b.layout.size()));
    b.adapter->connect();
    bound_.push_back(std::move(b));
  }
  set_status(BindingStatus::Connecting);
  set_fault("");
}

void HardwareBinding::cycle(double dt) {
  if (!built_ || built_config_ != config()) {
    try {
      configure();
    } catch (const std::exception& e) {
      disconnect();
      built_ = true;  // not again until the config changes
      built_config_ = config();
      holding_ = true;
      set_fault_state("config '" + config() + "': " + e.what());
      return;
    }
  }
  if (!active()) {
    commanded_ = false;
    return;
  }
  if (bound_.empty()) return;  // a bad configuration: holding in Fault
  KinematicTree* t = tree();
  if (t == nullptr) {
    set_fault_state("no KinematicTree on the binding's node");
    return;
  }
  const Model& m = t->model();
  const auto n = static_cast<std::size_t>(m.dof());
  const bool have_command = commanded_ && !holding_ && command_q_.size() == n;
  commanded_ = false;

  std::vector<double> part_q, part_qd;
  for (Bound& b : bound_) {
    if (have_command) {
      part_q.clear();
      part_qd.clear();
      for (int i : b.layout) {
        part_q.push_back(command_q_[static_cast<std::size_t>(i)]);
        part_qd.push_back(command_qd_[static_cast<std::size_t>(i)]);
      }
      b.adapter->write(part_q, part_qd);
    } else {
      b.adapter->hold();
    }
    b.adapter->cycle(dt);
  }

  // The database takes the measured state; joints bound to nothing take the command.
  std::vector<double> q = t->positions();
  std::vector<double> qd(n, 0.0);
  std::vector<bool> measured(n, false);
  bool all_fresh = true, all_valid = true;
  std::string why;
  for (const Bound& b : bound_) {
    const JointState& s = b.adapter->read();
    all_fresh &= s.fresh && b.adapter->fault() == AdapterFault::None;
    all_valid &= s.valid;
    if (b.adapter->fault() != AdapterFault::None && why.empty()) why = b.adapter->fault_message();
    if (!s.valid) continue;
    for (std::size_t k = 0; k < b.layout.size(); ++k) {
      const auto i = static_cast<std::size_t>(b.layout[k]);
      q[i] = s.position[k];
      qd[i] = s.velocity[k];
      measured[i] = true;
    }
  }
  if (have_command)
    for (std::size_t i = 0; i < n; ++i)
      if (!measured[i]) {
        q[i] = command_q_[i];
        qd[i] = command_qd_[i];
      }
  t->set_positions(q);
  const std::vector<DofInfo> layout(m.layout().begin(), m.layout().end());
  for (std::size_t i = 0; i < n; ++i)
    if (layout[i].axis_index == 0 && layout[i].joint != nullptr)
      const_cast<KinematicJoint*>(layout[i].joint)->set_velocity(measured[i] && !all_fresh ? 0.0 : qd[i]);

  const bool was_holding = holding_;
  holding_ = !all_fresh;
  if (!why.empty()) {
    set_fault_state(why);
  } else if (all_fresh) {
    set_status(BindingStatus::Running);
    if (!fault().empty()) set_fault("");
  } else if (!all_valid) {
    set_status(BindingStatus::Connecting);
  }
  // else: a lost answer without a fault yet; status stays, the controller holds this cycle.
  if (was_holding && !holding_) ++synchronisations_;
}

}  // namespace vsd::robotics
