# cmake -DINPUT=x.spv -DOUTPUT=x.spv.cpp -DSYMBOL=kX -DNAMESPACE=a::b -DHEADER=path/H.h -P EmbedSpirv.cmake
# Writes the SPIR-V words as a uint32_t array (SPIR-V is little-endian words on disk).
file(READ ${INPUT} hex HEX)
string(LENGTH "${hex}" num_hex)
math(EXPR remainder "${num_hex} % 8")
if(num_hex EQUAL 0 OR NOT remainder EQUAL 0)
  message(FATAL_ERROR "${INPUT} is not a SPIR-V module (${num_hex} hex digits)")
endif()
# Byte order aa bb cc dd on disk is the word 0xddccbbaa.
string(REGEX REPLACE "([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])"
       "0x\\4\\3\\2\\1u," words "${hex}")
string(REGEX REPLACE "((0x[0-9a-f]+u,){8})" "\\1\n" words "${words}")
file(WRITE ${OUTPUT} "// Generated from ${INPUT} by cmake/EmbedSpirv.cmake; do not edit.
#include \"${HEADER}\"

namespace ${NAMESPACE} {
namespace {
alignas(4) const uint32_t kWords[] = {
${words}
};
}  // namespace
const std::span<const uint32_t> ${SYMBOL}(kWords);
}  // namespace ${NAMESPACE}
")
