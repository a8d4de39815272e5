// libFuzzer entry (clang: cmake -DPLATE_FUZZ=ON with CXX=clang++, see docs/guide.md, "Reliability"):
// coverage-guided exploration of the same target the replay runs (fuzz_one.hpp). Inputs it finds
// that reach new behaviour go into tests/fuzz/corpus/, which ctest replays.
#include "fuzz_one.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    plate::fuzz::run_one(std::string(reinterpret_cast<const char*>(data), size));
    return 0;
}
