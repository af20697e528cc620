// Small text helpers the REPL session's files share.
#pragma once

#include <fmt/format.h>

#include <charconv>
#include <cstdint>
#include <optional>
#include <string>

namespace plant::cli {

// A whole number written with digits only, as the REPL's counts and seeds are.
inline std::optional<std::uint64_t> whole_number(const std::string& text) {
    std::uint64_t v = 0;
    auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size()) return std::nullopt;
    return v;
}

inline std::string modules(std::size_t n) {
    return fmt::format("{} module{}", n, n == 1 ? "" : "s");
}

inline std::string trim(const std::string& s) {
    std::size_t b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

} // namespace plant::cli
