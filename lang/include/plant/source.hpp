// Source files and spans. A span is a byte range in one loaded file; line and column are
// computed on demand so that every AST node can carry its span cheaply.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace plant {

struct Span {
    std::uint32_t file = 0;  // index into SourceManager; 0 is "no file"
    std::uint32_t begin = 0; // byte offset
    std::uint32_t end = 0;   // one past the last byte
    bool valid() const { return file != 0; }
};

struct LineCol {
    std::uint32_t line = 0; // 1-based
    std::uint32_t col = 0;  // 1-based, in bytes
};

class SourceFile {
  public:
    SourceFile(std::string name, std::string text);
    const std::string& name() const { return name_; }
    const std::string& text() const { return text_; }
    LineCol line_col(std::uint32_t offset) const;
    std::string_view line_text(std::uint32_t line) const; // without the newline
    std::uint32_t offset_of(std::uint32_t line, std::uint32_t col) const;

  private:
    std::string name_;
    std::string text_;
    std::vector<std::uint32_t> line_starts_;
};

// Owns every file read during one compilation (the main grammar and its imports).
class SourceManager {
  public:
    SourceManager();
    std::uint32_t add(std::string name, std::string text);
    const SourceFile& file(std::uint32_t id) const { return *files_.at(id); }
    std::size_t size() const { return files_.size(); }

  private:
    std::vector<std::unique_ptr<SourceFile>> files_;
};

} // namespace plant
