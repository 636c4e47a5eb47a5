/** @file
 *  @brief Shared fixture of the vsd benchmarks: the same little "robot" written four ways.
 *
 *  - `RawRobot`: a plain struct, the floor every access is compared with;
 *  - `Robot`: a built-in vsd class (VSD_INSTANCE / VSD_PROPERTY, base vsd::Node);
 *  - `runtime_robot_class()`: a run-time class with the same properties, made with vsd::ClassBuilder
 *    on the same base vsd::Node;
 *  - the peers (RTTR, Qt) declare their own twin in their benchmark files.
 *
 *  Rules every benchmark follows so that the numbers are honest:
 *  - written values come from `value(i)`, a table of 64 distinct doubles indexed by the loop counter, so no
 *    store can be elided as "same value again", no setter can skip an equal value, and the loop carries no
 *    floating-point dependency chain that would bound it (an `x += 1.0` chain costs ~4 cycles/iteration);
 *  - every result goes through benchmark::DoNotOptimize and every store is followed by
 *    benchmark::ClobberMemory, so nothing is hoisted out of the loop or sunk after it;
 *  - every listener keeps its own state (`Listener`), and the call counts are checked after the loop.
 */
#pragma once

#include <benchmark/benchmark.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vsd/core/environment.hpp>
#include <vsd/core/node.hpp>
#include <vsd/core/registry.hpp>
#include <vsd/core/sim_state.hpp>

namespace bench {

/// The plain struct with the same fields as Robot.
struct RawRobot {
  double speed = 1.0;
  double heading = 0.0;
  int battery = 100;
};

}  // namespace bench

/// The built-in vsd class.
class Robot : public vsd::Node {
  VSD_INSTANCE(Robot, vsd::Node)
  VSD_PROPERTY(double, speed, 1.0)
  VSD_PROPERTY(double, heading, 0.0)
  VSD_PROPERTY(int, battery, 100)
};

namespace bench {

/// The run-time twin of Robot ("RtRobot", base vsd::Node), defined once in the global Registry.
inline const vsd::MetaInstance& runtime_robot_class() {
  static const vsd::MetaInstance& cls = vsd::ClassBuilder("RtRobot", vsd::Node::static_meta())
                                            .property<double>("speed", 1.0)
                                            .property<double>("heading", 0.0)
                                            .property<int>("battery", 100)
                                            .define();
  return cls;
}

/// 64 distinct values written by the set benchmarks.
inline constexpr std::size_t value_count = 64;
inline constexpr std::array<double, value_count> values = [] {
  std::array<double, value_count> v{};
  for (std::size_t i = 0; i < value_count; ++i) v[i] = 0.5 + static_cast<double>(i) * 1.25;
  return v;
}();
inline double value(std::size_t i) noexcept { return values[i & (value_count - 1)]; }

/// Makes the optimizer produce @p v in a register. benchmark::DoNotOptimize(const T&) offers GCC an "r,m"
/// choice, and for a copy of a field GCC may pick "m" with the field itself as the operand, so that the
/// load being measured never happens; a register-only constraint forces it.
template <class T>
inline BENCHMARK_ALWAYS_INLINE void consume(const T& v) {
#if defined(__GNUC__) && defined(__x86_64__)
  if constexpr (std::is_floating_point_v<T>) {
    asm volatile("" : : "x"(v) : "memory");
  } else if constexpr (std::is_integral_v<T> || std::is_pointer_v<T>) {
    asm volatile("" : : "r"(v) : "memory");
  } else {
    benchmark::DoNotOptimize(v);
  }
#else
  benchmark::DoNotOptimize(v);
#endif
}

/// A listener with its own state: the number of calls and the sum of what it received.
struct Listener {
  std::uint64_t calls = 0;
  std::int64_t sum = 0;
  void on(int v) noexcept {
    ++calls;
    sum += v;
  }
};

/// Checks that every listener saw every emit; marks the benchmark as failed otherwise.
template <class Range>
void check_listeners(benchmark::State& state, const Range& listeners, std::uint64_t per_iteration = 1) {
  for (const Listener& l : listeners) {
    benchmark::DoNotOptimize(l.sum);
    if (l.calls != static_cast<std::uint64_t>(state.iterations()) * per_iteration) {
      state.SkipWithError("a listener missed calls");
      return;
    }
  }
}

/// An Environment with its main SimState; instances are created by the benchmarks.
struct World {
  vsd::Environment env;
  vsd::SimState& st = env.main_state();
};

}  // namespace bench
