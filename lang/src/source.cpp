#include "plant/source.hpp"

#include <algorithm>

namespace plant {

SourceFile::SourceFile(std::string name, std::string text) : name_(std::move(name)), text_(std::move(text)) {
    line_starts_.push_back(0);
    for (std::uint32_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') line_starts_.push_back(i + 1);
}

LineCol SourceFile::line_col(std::uint32_t offset) const {
    auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    auto line = static_cast<std::uint32_t>(it - line_starts_.begin());
    return {line, offset - line_starts_[line - 1] + 1};
}

std::string_view SourceFile::line_text(std::uint32_t line) const {
    if (line == 0 || line > line_starts_.size()) return {};
    std::uint32_t b = line_starts_[line - 1];
    std::uint32_t e =
        line < line_starts_.size() ? line_starts_[line] : static_cast<std::uint32_t>(text_.size());
    std::string_view s(text_.data() + b, e - b);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.remove_suffix(1);
    return s;
}

std::uint32_t SourceFile::offset_of(std::uint32_t line, std::uint32_t col) const {
    if (line == 0 || line > line_starts_.size()) return static_cast<std::uint32_t>(text_.size());
    return std::min<std::uint32_t>(line_starts_[line - 1] + col - 1,
                                   static_cast<std::uint32_t>(text_.size()));
}

SourceManager::SourceManager() {
    files_.push_back(std::make_unique<SourceFile>("<none>", ""));
}

std::uint32_t SourceManager::add(std::string name, std::string text) {
    files_.push_back(std::make_unique<SourceFile>(std::move(name), std::move(text)));
    return static_cast<std::uint32_t>(files_.size() - 1);
}

} // namespace plant
