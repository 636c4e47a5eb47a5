// Property access: typed (the generated getter/setter), generic by MetaProperty handle, generic by name,
// on a built-in class and on a run-time class, against a raw struct member and against the peers (RTTR
// property handles and names, Qt QObject properties by name and by QMetaProperty).
//
// Every benchmark does one operation per iteration; BM_Baseline_Loop shows what the loop itself costs.
#include <cstddef>

#include "fixture.hpp"

#if VSD_BENCH_HAVE_RTTR
#include <rttr/registration>
#include <rttr/type>
#endif
#if VSD_BENCH_HAVE_QT
#include <QMetaProperty>
#include <QVariant>

#include "qt_peer.hpp"
#endif

namespace {

using bench::value;

// ---- fixtures ---------------------------------------------------------------------------------------------

/// One Robot (built-in class) and one RtRobot (run-time class) in a fresh Environment.
struct Robots {
  bench::World w;
  Robot& builtin = w.st.create<Robot>();
  vsd::SimStateInstance& runtime = w.st.create(bench::runtime_robot_class());
};

/// The raw struct lives on the heap like an instance does, and its address escapes once.
struct RawHolder {
  bench::RawRobot* raw = new bench::RawRobot;
  RawHolder() { benchmark::DoNotOptimize(raw); }
  ~RawHolder() { delete raw; }
  RawHolder(const RawHolder&) = delete;
  RawHolder& operator=(const RawHolder&) = delete;
};

// ---- baseline ---------------------------------------------------------------------------------------------

void BM_Baseline_Loop(benchmark::State& state) {
  for (auto _ : state) benchmark::ClobberMemory();
}
BENCHMARK(BM_Baseline_Loop);

// ---- typed access -----------------------------------------------------------------------------------------

void BM_Get_Raw(benchmark::State& state) {
  RawHolder h;
  for (auto _ : state) {
    const double v = h.raw->speed;
    bench::consume(v);
  }
}
BENCHMARK(BM_Get_Raw);

void BM_Get_Typed(benchmark::State& state) {
  Robots f;
  Robot& r = f.builtin;
  for (auto _ : state) {
    const double v = r.speed();
    bench::consume(v);
  }
}
BENCHMARK(BM_Get_Typed);

void BM_Set_Raw(benchmark::State& state) {
  RawHolder h;
  std::size_t i = 0;
  for (auto _ : state) {
    h.raw->speed = value(i++);
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(h.raw->speed);
}
BENCHMARK(BM_Set_Raw);

void BM_Set_Typed(benchmark::State& state) {
  Robots f;
  Robot& r = f.builtin;
  std::size_t i = 0;
  for (auto _ : state) {
    r.set_speed(value(i++));
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(r.speed());
}
BENCHMARK(BM_Set_Typed);

/// The slow path: one listener on the instance (r.on_changed()), so every store compares, copies the old
/// value, and emits.
void BM_Set_Typed_Observed(benchmark::State& state) {
  Robots f;
  Robot& r = f.builtin;
  bench::Listener l;
  vsd::Connection c =
      r.on_changed().connect([&l](vsd::SimStateInstance&, const vsd::MetaProperty&) { l.on(1); });
  std::size_t i = 0;
  for (auto _ : state) {
    r.set_speed(value(i++));
    benchmark::ClobberMemory();
  }
  bench::check_listeners(state, std::array{l});
}
BENCHMARK(BM_Set_Typed_Observed);

/// The other slow path: the SimState records (no listener); the recording grows during the run, so this
/// is the per-set cost of recording, amortised (see bench_transaction.cpp for bounded bundles).
void BM_Set_Typed_Recording(benchmark::State& state) {
  Robots f;
  Robot& r = f.builtin;
  f.w.st.start_recording();
  std::size_t i = 0;
  for (auto _ : state) {
    r.set_speed(value(i++));
    benchmark::ClobberMemory();
    if ((i & 0xFFFF) == 0) {  // keep the bundle bounded (about 2 MB) so that memory does not grow unbounded
      state.PauseTiming();
      benchmark::DoNotOptimize(f.w.st.take_recording());
      state.ResumeTiming();
    }
  }
}
BENCHMARK(BM_Set_Typed_Recording);

// ---- generic access by MetaProperty handle ---------------------------------------------------------------

template <bool Runtime>
vsd::SimStateInstance& pick(Robots& f) {
  if constexpr (Runtime) {
    return f.runtime;
  } else {
    return f.builtin;
  }
}

template <bool Runtime>
void BM_Get_ByHandle(benchmark::State& state) {
  Robots f;
  vsd::SimStateInstance& r = pick<Runtime>(f);
  const vsd::MetaProperty& prop = *r.meta().find_property("speed");
  for (auto _ : state) {
    const double v = prop.get<double>(r);
    bench::consume(v);
  }
}
BENCHMARK(BM_Get_ByHandle<false>)->Name("BM_Get_ByHandle_Builtin");
BENCHMARK(BM_Get_ByHandle<true>)->Name("BM_Get_ByHandle_Runtime");

template <bool Runtime>
void BM_Set_ByHandle(benchmark::State& state) {
  Robots f;
  vsd::SimStateInstance& r = pick<Runtime>(f);
  const vsd::MetaProperty& prop = *r.meta().find_property("speed");
  std::size_t i = 0;
  for (auto _ : state) {
    prop.set<double>(r, value(i++));
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(prop.get<double>(r));
}
BENCHMARK(BM_Set_ByHandle<false>)->Name("BM_Set_ByHandle_Builtin");
BENCHMARK(BM_Set_ByHandle<true>)->Name("BM_Set_ByHandle_Runtime");

/// By handle through a vsd::Value (the type-erased path, like RTTR's variant).
template <bool Runtime>
void BM_Get_ByHandle_Value(benchmark::State& state) {
  Robots f;
  vsd::SimStateInstance& r = pick<Runtime>(f);
  const vsd::MetaProperty& prop = *r.meta().find_property("speed");
  for (auto _ : state) {
    const vsd::Value v = prop.get_value(r);
    const double d = v.as<double>();
    bench::consume(d);
  }
}
BENCHMARK(BM_Get_ByHandle_Value<false>)->Name("BM_Get_ByHandle_Value_Builtin");

template <bool Runtime>
void BM_Set_ByHandle_Value(benchmark::State& state) {
  Robots f;
  vsd::SimStateInstance& r = pick<Runtime>(f);
  const vsd::MetaProperty& prop = *r.meta().find_property("speed");
  std::size_t i = 0;
  for (auto _ : state) {
    prop.set_value(r, vsd::Value(value(i++)));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Set_ByHandle_Value<false>)->Name("BM_Set_ByHandle_Value_Builtin");

// ---- generic access by name -------------------------------------------------------------------------------

// By name, two ways. "Literal": the name is a string literal in C++ code, so the compiler folds its
// hash into a constant. "Runtime name": the name comes from data (a script, a file, the network) and is
// hashed on every call; DoNotOptimize on the name each iteration keeps the compiler from hoisting that.

template <bool Runtime>
void BM_FindProperty(benchmark::State& state) {
  Robots f;
  vsd::SimStateInstance& r = pick<Runtime>(f);
  const std::string name = "speed";
  std::string_view view = name;
  for (auto _ : state) {
    benchmark::DoNotOptimize(view);
    const vsd::MetaProperty* p = r.meta().find_property(view);
    bench::consume(p);
  }
}
BENCHMARK(BM_FindProperty<false>)->Name("BM_FindProperty_Builtin");
BENCHMARK(BM_FindProperty<true>)->Name("BM_FindProperty_Runtime");

template <bool Runtime, bool Literal>
void BM_Get_ByName(benchmark::State& state) {
  Robots f;
  vsd::SimStateInstance& r = pick<Runtime>(f);
  const std::string name = "speed";
  std::string_view view = name;
  for (auto _ : state) {
    double v;
    if constexpr (Literal) {
      v = r.get<double>("speed");
    } else {
      benchmark::DoNotOptimize(view);
      v = r.get<double>(view);
    }
    bench::consume(v);
  }
}
BENCHMARK(BM_Get_ByName<false, false>)->Name("BM_Get_ByName_Builtin");
BENCHMARK(BM_Get_ByName<true, false>)->Name("BM_Get_ByName_Runtime");
BENCHMARK(BM_Get_ByName<false, true>)->Name("BM_Get_ByLiteralName_Builtin");

template <bool Runtime, bool Literal>
void BM_Set_ByName(benchmark::State& state) {
  Robots f;
  vsd::SimStateInstance& r = pick<Runtime>(f);
  const std::string name = "speed";
  std::string_view view = name;
  std::size_t i = 0;
  for (auto _ : state) {
    if constexpr (Literal) {
      r.set<double>("speed", value(i++));
    } else {
      benchmark::DoNotOptimize(view);
      r.set<double>(view, value(i++));
    }
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(r.get<double>("speed"));
}
BENCHMARK(BM_Set_ByName<false, false>)->Name("BM_Set_ByName_Builtin");
BENCHMARK(BM_Set_ByName<true, false>)->Name("BM_Set_ByName_Runtime");
BENCHMARK(BM_Set_ByName<false, true>)->Name("BM_Set_ByLiteralName_Builtin");

// ---- RTTR 0.9.6 -------------------------------------------------------------------------------------------
#if VSD_BENCH_HAVE_RTTR

struct RttrRobot {
  double speed = 1.0;
  double heading = 0.0;
  int battery = 100;
};

struct RttrHolder {
  RttrRobot* obj = new RttrRobot;
  RttrHolder() { benchmark::DoNotOptimize(obj); }
  ~RttrHolder() { delete obj; }
  RttrHolder(const RttrHolder&) = delete;
  RttrHolder& operator=(const RttrHolder&) = delete;
};

void BM_Rttr_Get_ByHandle(benchmark::State& state) {
  RttrHolder h;
  const rttr::property prop = rttr::type::get<RttrRobot>().get_property("speed");
  if (!prop.is_valid()) state.SkipWithError("RTTR: no property 'speed'");
  for (auto _ : state) {
    const double v = prop.get_value(*h.obj).to_double();
    bench::consume(v);
  }
}
BENCHMARK(BM_Rttr_Get_ByHandle);

void BM_Rttr_Set_ByHandle(benchmark::State& state) {
  RttrHolder h;
  const rttr::property prop = rttr::type::get<RttrRobot>().get_property("speed");
  std::size_t i = 0;
  for (auto _ : state) {
    const bool ok = prop.set_value(*h.obj, value(i++));
    benchmark::DoNotOptimize(ok);
    benchmark::ClobberMemory();
  }
  if (h.obj->speed == 1.0) state.SkipWithError("RTTR: set_value did not store");
}
BENCHMARK(BM_Rttr_Set_ByHandle);

void BM_Rttr_Get_ByName(benchmark::State& state) {
  RttrHolder h;
  const rttr::type t = rttr::type::get<RttrRobot>();
  for (auto _ : state) {
    const double v = t.get_property_value("speed", *h.obj).to_double();
    bench::consume(v);
  }
}
BENCHMARK(BM_Rttr_Get_ByName);

void BM_Rttr_Set_ByName(benchmark::State& state) {
  RttrHolder h;
  const rttr::type t = rttr::type::get<RttrRobot>();
  std::size_t i = 0;
  for (auto _ : state) {
    const bool ok = t.set_property_value("speed", *h.obj, value(i++));
    benchmark::DoNotOptimize(ok);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Rttr_Set_ByName);

#endif  // VSD_BENCH_HAVE_RTTR

// ---- Qt 5 -------------------------------------------------------------------------------------------------
#if VSD_BENCH_HAVE_QT

QMetaProperty qt_speed() {
  const QMetaObject& mo = bench::QtRobot::staticMetaObject;
  return mo.property(mo.indexOfProperty("speed"));
}

void BM_Qt_Set_Typed(benchmark::State& state) {
  bench::QtRobot obj;
  std::size_t i = 0;
  for (auto _ : state) {
    obj.setSpeed(value(i++));
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(obj.speed());
}
BENCHMARK(BM_Qt_Set_Typed);

void BM_Qt_Get_ByHandle(benchmark::State& state) {
  bench::QtRobot obj;
  const QMetaProperty mp = qt_speed();
  for (auto _ : state) {
    const double v = mp.read(&obj).toDouble();
    bench::consume(v);
  }
}
BENCHMARK(BM_Qt_Get_ByHandle);

void BM_Qt_Set_ByHandle(benchmark::State& state) {
  bench::QtRobot obj;
  const QMetaProperty mp = qt_speed();
  std::size_t i = 0;
  for (auto _ : state) {
    const bool ok = mp.write(&obj, QVariant(value(i++)));
    benchmark::DoNotOptimize(ok);
    benchmark::ClobberMemory();
  }
  if (obj.speed() == 1.0) state.SkipWithError("Qt: QMetaProperty::write did not store");
}
BENCHMARK(BM_Qt_Set_ByHandle);

void BM_Qt_Get_ByName(benchmark::State& state) {
  bench::QtRobot obj;
  for (auto _ : state) {
    const double v = obj.property("speed").toDouble();
    bench::consume(v);
  }
}
BENCHMARK(BM_Qt_Get_ByName);

void BM_Qt_Set_ByName(benchmark::State& state) {
  bench::QtRobot obj;
  std::size_t i = 0;
  for (auto _ : state) {
    const bool ok = obj.setProperty("speed", QVariant(value(i++)));
    benchmark::DoNotOptimize(ok);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Qt_Set_ByName);

#endif  // VSD_BENCH_HAVE_QT

}  // namespace

#if VSD_BENCH_HAVE_RTTR
RTTR_REGISTRATION {
  rttr::registration::class_<RttrRobot>("RttrRobot")
      .property("speed", &RttrRobot::speed)
      .property("heading", &RttrRobot::heading)
      .property("battery", &RttrRobot::battery);
}
#endif
