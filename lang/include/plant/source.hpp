// Source files and spans. A span is a byte range in one loaded file; line and column are
// computed on demand so that every AST node can carry its span cheaply.
#pragma once

#include <cstddef>
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
    // The line number messages give: a line's own, unless the text was put together from lines
    // typed elsewhere (the REPL's session), which then names each line by where it was typed.
    // `shown[i]` is shown for line i + 1; 0 or a line past the end keeps its own number.
    void show_lines(std::vector<std::uint32_t> shown) { shown_lines_ = std::move(shown); }
    LineCol shown(LineCol at) const;
    LineCol shown_line_col(std::uint32_t offset) const { return shown(line_col(offset)); }

  private:
    std::string name_;
    std::string text_;
    std::vector<std::uint32_t> line_starts_;
    std::vector<std::uint32_t> shown_lines_;
};

// Owns every file read during one compilation (the main grammar and its imports).
class SourceManager {
  public:
    SourceManager();
    std::uint32_t add(std::string name, std::string text);
    const SourceFile& file(std::uint32_t id) const { return *files_.at(id); }
    void show_lines(std::uint32_t id, std::vector<std::uint32_t> shown) {
        files_.at(id)->show_lines(std::move(shown));
    }
    std::size_t size() const { return files_.size(); }

  private:
    std::vector<std::unique_ptr<SourceFile>> files_;
};

// Reading a file a grammar names (a source, an import, a mesh): only a regular file is read, and
// only up to a size cap checked before reading, so a FIFO, a device (/dev/zero) or a huge file is
// refused instead of blocking or filling memory.
enum class ReadFailure { None, Missing, Denied, NotRegular, TooLarge, Failed };

inline constexpr std::size_t kMaxSourceBytes = std::size_t{64} << 20; // sources and mesh files

// Reads `path` whole into `out`. With `regular_only` false (the grammar the user names on the
// command line, which may be a pipe) other kinds of file are read too, still up to `max_bytes`.
ReadFailure read_input_file(const std::string& path, std::string& out,
                            std::size_t max_bytes = kMaxSourceBytes, bool regular_only = true);

// Reads an open descriptor to its end into `out` (standard input for the grammar '-'), up to
// `max_bytes`; `out` is left as it was on a failure.
ReadFailure read_descriptor(int fd, std::string& out, std::size_t max_bytes = kMaxSourceBytes);

// Why it failed, for a message: "no such file", "it is not a regular file", ...
std::string describe(ReadFailure f, std::size_t max_bytes = kMaxSourceBytes);

} // namespace plant
