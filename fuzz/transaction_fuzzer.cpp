// Fuzzes SimState::apply: any bundle must either apply or throw vsd::Error and change nothing.
#include <cstdint>
#include <cstdlib>

#include "fuzz_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vsd::Environment env;
  vsd::SimState& state = env.main_state();
  fuzz::build(state);
  vsd::SimState& before = env.create_state("before");
  before.copy_from(state);
  try {
    state.apply(vsd::Transaction::from_bytes(std::vector<std::uint8_t>(data, data + size)));
  } catch (const vsd::Error&) {
    if (!state.equals(before)) std::abort();  // a rejected bundle must change nothing
    return 0;
  }
  if (!fuzz::counts_consistent(state)) std::abort();
  return 0;
}
