// Fuzzes the text (JSON) loader: any input must either load or throw vsd::Error, leaving the target state
// untouched; a loaded state must be consistent, and its text must load again to an equal state.
#include <cstdint>
#include <cstdlib>

#include "fuzz_model.hpp"
#include "vsd/io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vsd::Registry registry;  // classes a file defines stay with this input
  registry.add<fuzz::FzRobot>();
  vsd::Environment env(0, registry);
  vsd::SimState& state = env.main_state();
  // Inputs that do not look like text go to the binary fuzzer's loader: here they must say so.
  try {
    vsd::io::load_bytes(state, std::span<const std::uint8_t>(data, size), "fuzz.json");
  } catch (const vsd::Error&) {
    if (state.size() != 1) std::abort();  // a rejected file must change nothing
    return 0;
  }
  if (!fuzz::counts_consistent(state)) std::abort();
  vsd::SimState& again = env.create_state("again");
  vsd::io::load_bytes(again, vsd::io::save_bytes(state, vsd::io::Format::Text), "resaved.json");
  if (!again.equals(state)) std::abort();
  return 0;
}
