// Emitting a signal `void(int)` with 0, 1 and 10 listeners: vsd::Signal against Boost.Signals2,
// libsigc++ 3 and a Qt 5 direct connection. Every listener keeps its own state (bench::Listener: its own
// call count and sum); after the loop every listener must have seen every emit.
//
// Listeners are lambdas capturing a pointer to their Listener (vsd, Boost, sigc++), or receiver QObjects
// with a pointer-to-member slot (Qt, its idiom). The argument changes on every emit.
#include <cstddef>
#include <memory>
#include <vector>

#include "fixture.hpp"

#if VSD_BENCH_HAVE_BOOST
#include <boost/signals2/dummy_mutex.hpp>
#include <boost/signals2/signal.hpp>
#include <boost/signals2/signal_type.hpp>
#endif
#if VSD_BENCH_HAVE_SIGC
#include <sigc++/sigc++.h>
#endif
#if VSD_BENCH_HAVE_QT
#include "qt_peer.hpp"
#endif

namespace {

void listener_args(benchmark::internal::Benchmark* b) { b->ArgName("listeners")->Arg(0)->Arg(1)->Arg(10); }

// ---- vsd --------------------------------------------------------------------------------------------------

void BM_Emit_Vsd(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<bench::Listener> ls(n);
  vsd::Signal<void(int)> sig;
  std::vector<vsd::Connection> cs;
  for (auto& l : ls) cs.push_back(sig.connect([p = &l](int v) { p->on(v); }));
  benchmark::DoNotOptimize(&sig);  // the signal escapes: its state is reloaded after every ClobberMemory
  int v = 0;
  for (auto _ : state) {
    sig.emit(v++);
    benchmark::ClobberMemory();
  }
  bench::check_listeners(state, ls);
}
BENCHMARK(BM_Emit_Vsd)->Apply(listener_args);

/// vsd's allocation-free member-function listeners: `sig.connect<&Listener::on>(l)`.
void BM_Emit_Vsd_Member(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<bench::Listener> ls(n);
  vsd::Signal<void(int)> sig;
  std::vector<vsd::Connection> cs;
  for (auto& l : ls) cs.push_back(sig.connect<&bench::Listener::on>(l));
  benchmark::DoNotOptimize(&sig);
  int v = 0;
  for (auto _ : state) {
    sig.emit(v++);
    benchmark::ClobberMemory();
  }
  bench::check_listeners(state, ls);
}
BENCHMARK(BM_Emit_Vsd_Member)->ArgName("listeners")->Arg(1)->Arg(10);

// ---- Boost.Signals2 ---------------------------------------------------------------------------------------
#if VSD_BENCH_HAVE_BOOST

template <class Sig>
void emit_boost(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<bench::Listener> ls(n);
  Sig sig;
  for (auto& l : ls) sig.connect([p = &l](int v) { p->on(v); });
  benchmark::DoNotOptimize(&sig);
  int v = 0;
  for (auto _ : state) {
    sig(v++);
    benchmark::ClobberMemory();
  }
  bench::check_listeners(state, ls);
}

/// The default signal (boost::signals2::mutex, thread-safe).
void BM_Emit_Boost(benchmark::State& state) { emit_boost<boost::signals2::signal<void(int)>>(state); }
BENCHMARK(BM_Emit_Boost)->Apply(listener_args);

/// Single-threaded configuration (dummy_mutex): Boost's best case, the same threading model as vsd.
using BoostUnlocked =
    boost::signals2::signal_type<void(int),
                                 boost::signals2::keywords::mutex_type<boost::signals2::dummy_mutex>>::type;
void BM_Emit_Boost_DummyMutex(benchmark::State& state) { emit_boost<BoostUnlocked>(state); }
BENCHMARK(BM_Emit_Boost_DummyMutex)->Apply(listener_args);

#endif  // VSD_BENCH_HAVE_BOOST

// ---- libsigc++ 3 ------------------------------------------------------------------------------------------
#if VSD_BENCH_HAVE_SIGC

void BM_Emit_Sigc(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<bench::Listener> ls(n);
  sigc::signal<void(int)> sig;
  for (auto& l : ls) sig.connect([p = &l](int v) { p->on(v); });
  benchmark::DoNotOptimize(&sig);
  int v = 0;
  for (auto _ : state) {
    sig.emit(v++);
    benchmark::ClobberMemory();
  }
  bench::check_listeners(state, ls);
}
BENCHMARK(BM_Emit_Sigc)->Apply(listener_args);

#endif  // VSD_BENCH_HAVE_SIGC

// ---- Qt 5 -------------------------------------------------------------------------------------------------
#if VSD_BENCH_HAVE_QT

void BM_Emit_Qt(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  bench::QtSender sender;
  std::vector<std::unique_ptr<bench::QtReceiver>> rs;
  for (std::size_t k = 0; k < n; ++k) {
    rs.push_back(std::make_unique<bench::QtReceiver>());
    QObject::connect(&sender, &bench::QtSender::ping, rs.back().get(), &bench::QtReceiver::onPing,
                     Qt::DirectConnection);
  }
  int v = 0;
  for (auto _ : state) {
    sender.fire(v++);
    benchmark::ClobberMemory();
  }
  for (const auto& r : rs) {
    benchmark::DoNotOptimize(r->sum);
    if (r->calls != static_cast<std::uint64_t>(state.iterations()))
      state.SkipWithError("a Qt receiver missed calls");
  }
}
BENCHMARK(BM_Emit_Qt)->Apply(listener_args);

#endif  // VSD_BENCH_HAVE_QT

}  // namespace
