// Minimal logging on top of fmt: info to stdout, warnings and errors to stderr.
#pragma once
#include <fmt/core.h>
#include <cstdio>

namespace ff::log {
inline bool& quiet() { static bool q = false; return q; }
template <class... A> void info(fmt::format_string<A...> f, A&&... a) {
  if (!quiet()) { fmt::print(stdout, f, std::forward<A>(a)...); std::fputc('\n', stdout); std::fflush(stdout); }
}
template <class... A> void warn(fmt::format_string<A...> f, A&&... a) {
  fmt::print(stderr, "warning: "); fmt::print(stderr, f, std::forward<A>(a)...); std::fputc('\n', stderr);
}
template <class... A> void error(fmt::format_string<A...> f, A&&... a) {
  fmt::print(stderr, "error: "); fmt::print(stderr, f, std::forward<A>(a)...); std::fputc('\n', stderr);
}
}  // namespace ff::log
