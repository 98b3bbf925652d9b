// libFuzzer target: the .hair (Cem Yuksel) reader, parseHairBytes() (oracle: groom_fuzzer.h).
#include "groom_fuzzer.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return hairvox::fuzz::fuzzGroomReader(&hairvox::parseHairBytes, data, size);
}
