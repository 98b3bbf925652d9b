// libFuzzer target: the .tfx (AMD TressFX 4) reader, parseTfxBytes() (oracle: groom_fuzzer.h).
#include "groom_fuzzer.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return hairvox::fuzz::fuzzGroomReader(&hairvox::parseTfxBytes, data, size);
}
