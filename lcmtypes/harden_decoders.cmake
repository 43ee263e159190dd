# Rewrites the C++ decoders lcm-gen writes so that no message, however
# malformed, makes them throw or allocate beyond its own size: lcm-gen checks
# only the upper bound of a string length (a length of 0 or -1 reaches
# std::string::assign(p, len - 1)) and no bound at all on an array count
# before std::vector::resize (a count of -1 throws, a count of 2^27 in a
# 700-byte message allocates gigabytes). After this pass, a string length
# must be at least 1 (the terminating NUL) and a count non-negative and no
# larger than the bytes left can hold (the fewest bytes of one element:
# lcm_wire_bounds.hpp); the decoder then returns -1, as for any message that
# does not decode.
#
#   cmake -DDIR=<folder of generated .hpp> -P harden_decoders.cmake
#
# Fails the build when lcm-gen's output no longer has the shapes rewritten
# here (a new lcm-gen): then this script needs a look.
file(GLOB headers "${DIR}/*.hpp")
if(NOT headers)
  message(FATAL_ERROR "harden_decoders: no headers in ${DIR}")
endif()
set(name "[]A-Za-z0-9_[]+")
foreach(h ${headers})
  file(READ "${h}" text)
  if(text MATCHES "decoders hardened")
    continue()
  endif()
  # Strings (and elements of string arrays).
  string(REGEX REPLACE "if\\((__[A-Za-z0-9_]+) > maxlen - pos\\) return -1;"
         "if(\\1 < 1 || \\1 > maxlen - pos) return -1;" text "${text}")
  # The outer dimension of a two-dimensional array whose inner dimension is a
  # count: its elements are empty when that count is 0, so only then it is not
  # bounded by the bytes left (its count bounds an earlier array in every
  # message of this project).
  string(REGEX REPLACE
         "this->(${name})\\.resize\\(this->([A-Za-z0-9_]+)\\);([ \n]*for \\(int a0 = 0; a0 < this->[A-Za-z0-9_]+; a0\\+\\+\\) {[ \n]*if\\(this->([A-Za-z0-9_]+)\\) {)"
         "if(this->\\2 < 0 || (this->\\4 != 0 && this->\\2 > maxlen - pos)) return -1;\n    this->\\1.resize(static_cast<std::size_t>(this->\\2));\\3"
         text "${text}")
  # Every other array: its count times the fewest bytes an element takes
  # (lcm_wire_bounds.hpp) must fit in the bytes left.
  string(REGEX REPLACE "this->(${name})\\.resize\\(this->([A-Za-z0-9_]+)\\);"
         "if(::acyclic::lcm_wire::tooMany(this->\\2, maxlen - pos, this->\\1)) return -1;\n        this->\\1.resize(static_cast<std::size_t>(this->\\2));"
         text "${text}")
  if(text MATCHES "\\.resize\\(this->" OR text MATCHES "if\\(__[A-Za-z0-9_]+ > maxlen - pos\\)")
    message(FATAL_ERROR "harden_decoders: ${h} has a decoder shape this script does not know")
  endif()
  string(REPLACE "#include <lcm/lcm_coretypes.h>" "#include <lcm/lcm_coretypes.h>\n#include <cstddef>\n#include \"lcm_wire_bounds.hpp\"\n// decoders hardened (lcmtypes/harden_decoders.cmake)" text "${text}")
  if(NOT text MATCHES "decoders hardened")
    message(FATAL_ERROR "harden_decoders: ${h}: no #include <lcm/lcm_coretypes.h>")
  endif()
  file(WRITE "${h}" "${text}")
endforeach()
