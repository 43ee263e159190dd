#pragma once
// For the interposers of libacyclic_ipopt_interposers.so: the definition of
// `symbol` that theirs hides (the next one in the lookup order), or abort
// naming `what`: an interposer without the function it wraps cannot work.
#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>

namespace acyclic {

template <class Fn>
Fn nextDefinition(const char* symbol, const char* what) {
  auto f = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, symbol));
  if (!f) {
    std::fprintf(stderr, "acyclic: %s not found behind its interposer\n", what);
    std::abort();
  }
  return f;
}

}  // namespace acyclic
