#include "plant/source.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace plant {

SourceFile::SourceFile(std::string name, std::string text) : name_(std::move(name)), text_(std::move(text)) {
    // A carriage return not followed by a line feed (the classic Mac OS line ending) ends a line
    // too: read as a space, a comment would run to the end of the file and every diagnostic would
    // be on line 1. Turned into '\n', so every offset stays where it was.
    for (std::size_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\r' && (i + 1 == text_.size() || text_[i + 1] != '\n')) text_[i] = '\n';
    line_starts_.push_back(0);
    for (std::uint32_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') line_starts_.push_back(i + 1);
}

LineCol SourceFile::line_col(std::uint32_t offset) const {
    auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    auto line = static_cast<std::uint32_t>(it - line_starts_.begin());
    return {line, offset - line_starts_[line - 1] + 1};
}

LineCol SourceFile::shown(LineCol at) const {
    if (at.line >= 1 && at.line <= shown_lines_.size() && shown_lines_[at.line - 1] != 0)
        at.line = shown_lines_[at.line - 1];
    return at;
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

ReadFailure read_input_file(const std::string& path, std::string& out, std::size_t max_bytes,
                            bool regular_only) {
    // stat first so a FIFO or a device is never opened; then open without blocking (a FIFO
    // swapped in meanwhile opens at once) and check the open file again
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0)
        return errno == EACCES                       ? ReadFailure::Denied
               : errno == ENOENT || errno == ENOTDIR ? ReadFailure::Missing
                                                     : ReadFailure::Failed;
    // a device is refused even where a pipe is read (the grammar named on the command line):
    // /dev/zero never ends, a terminal waits for typing
    auto refused = [&](const struct stat& s) {
        return S_ISDIR(s.st_mode) || S_ISCHR(s.st_mode) || S_ISBLK(s.st_mode) ||
               (regular_only && !S_ISREG(s.st_mode));
    };
    if (refused(st)) return ReadFailure::NotRegular;
    if (S_ISREG(st.st_mode) && static_cast<std::uint64_t>(st.st_size) > max_bytes)
        return ReadFailure::TooLarge;
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | (regular_only ? O_NONBLOCK : 0));
    if (fd < 0) return errno == EACCES ? ReadFailure::Denied : ReadFailure::Failed;
    ReadFailure result = ReadFailure::None;
    if (::fstat(fd, &st) != 0) {
        result = ReadFailure::Failed;
    } else if (refused(st)) {
        result = ReadFailure::NotRegular;
    } else {
        result = read_descriptor(fd, out, max_bytes); // (a file that grew is caught there too)
    }
    ::close(fd);
    return result;
}

ReadFailure read_descriptor(int fd, std::string& out, std::size_t max_bytes) {
    std::string text;
    char buf[1 << 16];
    while (true) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return ReadFailure::Failed;
        if (n == 0) break;
        if (text.size() + static_cast<std::size_t>(n) > max_bytes) return ReadFailure::TooLarge;
        text.append(buf, static_cast<std::size_t>(n));
    }
    out = std::move(text);
    return ReadFailure::None;
}

std::string describe(ReadFailure f, std::size_t max_bytes) {
    switch (f) {
    case ReadFailure::None:
        return "read";
    case ReadFailure::Missing:
        return "no such file";
    case ReadFailure::Denied:
        return "permission denied";
    case ReadFailure::NotRegular:
        return "it is not a regular file (a folder, a device or a pipe)";
    case ReadFailure::TooLarge:
        return fmt::format("it is larger than {} MB, the most plant reads", max_bytes >> 20);
    case ReadFailure::Failed:
        break;
    }
    return "it cannot be read";
}

} // namespace plant
