// Net invocation (docs/soml.md 4.11 and 5.5): an invoking transition fires in two halves. The first
// creates a net instance (a node of the net's run-time class, derived from soml::Invocation) as a child of
// the transition's node, sets its value parameters, builds its places and transitions through the
// ordinary path and puts one black token into its start place; the mark waits in the instance's `mark`
// property. The second half runs when a transition of the instance executes `finish v;` (which sets the
// instance's `result` and `finished` properties): the invoking transition's action runs with `result`
// bound to v, the instance (and every invocation nested in it) is deleted, and the invoking transition
// produces its output tokens. All of it is database state, so recording, replicas and vsd::io see it.
#include <cstring>

#include "program_impl.hpp"
#include "vsd/core/error.hpp"

namespace vsd::soml {

namespace {

// The value of property @p s of @p o as a register (and its string, vector or Value, for those kinds).
Val load_value(const PropSlot& s, const SimStateInstance& o, std::string& str, VecReg& vec, Value& x) {
  Val v{};
  const MetaProperty& p = *s.prop;
  const void* a = p.address(o);
  switch (s.kind) {
    case PK::I64:
      std::memcpy(&v.i, a, sizeof v.i);
      break;
    case PK::Bool:
      v.i = *static_cast<const bool*>(a) ? 1 : 0;
      break;
    case PK::Double:
      std::memcpy(&v.d, a, sizeof v.d);
      break;
    case PK::String:
      str = *static_cast<const std::string*>(a);
      break;
    case PK::Int:
    case PK::Enum:
      v.i = p.type().load_integer(a);
      break;
    case PK::Ref: {
      const SimStateInstance* t = static_cast<const RefBase*>(a)->get();
      v.id = t != nullptr ? t->id() : 0;
      break;
    }
    case PK::Vector:
      vector_load(p.type(), a, vec);
      break;
    case PK::Value:  // structs, vectors of structs and enums
      x = Value(p.type(), a);
      break;
    default:
      if (p.type().kind() == TypeKind::Float) {
        float f = 0;
        std::memcpy(&f, a, sizeof f);
        v.d = f;
        break;
      }
      throw Error("SOML++ run-time error: a net result of type " + p.type().name() + " cannot be read yet");
  }
  return v;
}

}  // namespace

SimStateInstance& ProgramImpl::start_invocation(const TransitionInfo& t, Transition& tn, std::uint64_t mark) {
  const ClassInfo& ci = *t.invoke;
  // A failure here (arguments, initialisers, constructors) is undone with the whole firing (fire()).
  SimStateInstance& inst = create_node(ci, &tn, ci.decl->name);
  const Id id = inst.id();
  auto& inv = static_cast<Invocation&>(inst);
  SimStateInstance* m = mark != 0 ? state_.find(mark) : nullptr;
  if (m != nullptr && m->as<Node>() != nullptr) inv.set_mark(SharedRef<Node>(m->as<Node>()));
  if (t.invoke_args >= 0) {
    Val self{};
    self.id = id;
    run(t.invoke_args, tn.id(), mark, &self, nullptr);
  }
  setup(ci, inst, nullptr, nullptr, 0);
  NetInst* n = net_of(id);
  if (n == nullptr || ci.start_place < 0)
    fail("net " + ci.decl->name + " has no start place to receive the invocation's token");
  put_token(*n->places[static_cast<std::size_t>(ci.start_place)], nullptr, 1);
  return inst;
}

bool ProgramImpl::finished(const NetInst& net) const {
  const SimStateInstance* o = state_.find(net.owner);
  const auto* inv = o != nullptr ? o->as<Invocation>() : nullptr;
  return inv != nullptr && inv->finished();
}

std::pair<NetInst*, int> ProgramImpl::complete_action(const NetInst& inner) {
  auto& inv = *state_.find(inner.owner)->as<Invocation>();
  const auto ci_it = by_meta_.find(&inv.meta());
  const ClassInfo* ci = ci_it != by_meta_.end() ? ci_it->second : nullptr;
  const std::string name = ci != nullptr ? ci->decl->name : inv.meta().name();
  {
    // An error here leaves `finished` set; the caller undoes the whole firing, that included.
    // The invoking transition: the instance's parent, a transition of a live net that invokes this net.
    Node* parent = inv.parent();
    auto it = parent != nullptr ? node_net_.find(parent->id()) : node_net_.end();
    NetInst* outer = it != node_net_.end() && !it->second->dead ? it->second : nullptr;
    int index = -1;
    for (std::size_t k = 0; outer != nullptr && k < outer->transitions.size(); ++k)
      if (outer->transitions[k] == parent) index = static_cast<int>(k);
    if (index < 0) fail("net " + name + " finished, but no transition invoked it (its invoker is gone)");
    const TransitionInfo& t = outer->cls->transitions[static_cast<std::size_t>(index)];
    if (t.invoke != ci)
      fail("net " + name + " finished, but transition " + t.decl->name + " invokes " +
           (t.invoke != nullptr ? "net " + t.invoke->decl->name : std::string("no net")) +
           ": its result does not fit");
    const SimStateInstance* m = inv.mark().get();
    const std::uint64_t mark = m != nullptr ? m->id() : 0;
    if (t.action >= 0) {
      std::string str;
      VecReg vec;
      Value x;
      Val r{};
      if (ci->result_slot >= 0)
        r = load_value(image().props[static_cast<std::size_t>(ci->result_slot)], inv, str, vec, x);
      run(t.action, parent->id(), mark, &r, &str, nullptr, &vec, nullptr, &x);
    }
    return {outer, index};
  }
}

void ProgramImpl::complete_outputs(NetInst& outer, int index, std::uint64_t instance) {
  SimStateInstance* o = state_.find(instance);
  std::uint64_t mark = 0;
  if (o != nullptr) {
    const SimStateInstance* m = o->as<Invocation>()->mark().get();
    mark = m != nullptr ? m->id() : 0;
    // The instance, its places, transitions and nested invocations go once the whole firing stands and
    // its trace is out (fire()): the outputs below may still fail, and the trace names its transition.
    finished_instance_ = instance;
  }
  if (outer.dead) return;
  const TransitionInfo& t = outer.cls->transitions[static_cast<std::size_t>(index)];
  std::vector<TokenMove> given;
  Place* to = produce(outer, t, mark, trace_ ? &given : nullptr);
  const auto ti = static_cast<std::uint32_t>(outer.first_ti + static_cast<std::uint32_t>(index));
  mark_dirty(ti);
  if (trace_)
    pending_.push_back(Firing{firings_,
                              outer.transitions[static_cast<std::size_t>(index)],
                              mark,
                              nullptr,
                              to,
                              FiringKind::Complete,
                              instance,
                              {},
                              std::move(given)});
}

}  // namespace vsd::soml
