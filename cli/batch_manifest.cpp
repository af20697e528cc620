#include "batch_manifest.hpp"

#include "plant/export.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

bool ends_with(const std::string& s, std::string_view tail) {
    return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (const char ch : s) {
        const auto c = static_cast<unsigned char>(ch);
        if (c == '"' || c == '\\')
            out += {'\\', ch};
        else if (c == '\n')
            out += "\\n";
        else if (c < 0x20 || c == 0x7f)
            out += fmt::format("\\u{:04x}", c);
        else
            out += ch;
    }
    return out + "\"";
}

// RFC 4180: a field with a comma, quote or line break is quoted, its quotes doubled.
std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
    std::string out = "\"";
    for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string seed_text(const ManifestRow& row) {
    return row.seed ? std::to_string(*row.seed) : std::string();
}

} // namespace

std::optional<ManifestFormat> manifest_format(const std::string& path) {
    if (ends_with(path, ".csv")) return ManifestFormat::Csv;
    if (ends_with(path, ".jsonl") || ends_with(path, ".ndjson")) return ManifestFormat::JsonLines;
    return std::nullopt;
}

std::string json_row(const ManifestRow& row, const std::vector<std::string>& param_names) {
    std::string params, outputs;
    for (std::size_t k = 0; k < row.params.size() && k < param_names.size(); ++k)
        params += (k ? "," : "") + json_string(param_names[k]) + ":" + row.params[k];
    for (std::size_t k = 0; k < row.outputs.size(); ++k)
        outputs += (k ? "," : "") + json_string(row.outputs[k]);
    return fmt::format("{{\"n\":{},\"seed\":{},\"params\":{{{}}},\"outputs\":[{}],\"modules\":{},"
                       "\"triangles\":{},\"ms\":{:.1f},\"status\":{},\"message\":{}}}",
                       row.n, row.seed ? std::to_string(*row.seed) : "null", params, outputs, row.modules,
                       row.triangles, row.ms, json_string(row.status), json_string(row.message));
}

std::string csv_header(const std::vector<std::string>& param_names) {
    std::string out = "n,seed";
    for (const auto& p : param_names) out += "," + csv_field(p);
    return out + ",outputs,modules,triangles,ms,status,message";
}

std::string csv_row(const ManifestRow& row) {
    std::string out = fmt::format("{},{}", row.n, seed_text(row));
    for (const auto& p : row.params) out += "," + p;
    std::string outputs;
    for (std::size_t k = 0; k < row.outputs.size(); ++k) outputs += (k ? ";" : "") + row.outputs[k];
    return out + fmt::format(",{},{},{},{:.1f},{},{}", csv_field(outputs), row.modules, row.triangles, row.ms,
                             row.status, csv_field(row.message));
}

ManifestWriter::ManifestWriter(const std::string& path, const BatchPlan& plan) : path_(path) {
    for (const auto& a : plan.axes) param_names_.push_back(a.name);
    if (path_.empty()) return;
    format_ = manifest_format(path_).value_or(ManifestFormat::JsonLines);
    const fs::path target(path_);
    std::error_code ec;
    if (!target.parent_path().empty()) fs::create_directories(target.parent_path(), ec);
    temp_ = (target.parent_path() /
             ("." + target.filename().string() + ".plant-tmp-" + std::to_string(::getpid())))
                .string();
    file_ = std::fopen(temp_.c_str(), "wx");
    if (!file_)
        throw ExportError(fmt::format("cannot write the manifest '{}': {}", path_, std::strerror(errno)));
    if (format_ == ManifestFormat::Csv) write(csv_header(param_names_) + "\n");
}

ManifestWriter::~ManifestWriter() {
    if (file_) {
        std::fclose(file_);
        ::unlink(temp_.c_str());
    }
}

void ManifestWriter::write(const std::string& text) {
    if (file_ && std::fwrite(text.data(), 1, text.size(), file_) != text.size()) failed_ = true;
}

void ManifestWriter::write_row(const ManifestRow& row) {
    write((format_ == ManifestFormat::Csv ? csv_row(row) : json_row(row, param_names_)) + "\n");
}

void ManifestWriter::add(std::uint64_t i, ManifestRow row) {
    std::lock_guard lock(mutex_);
    if (i != next_) {
        waiting_.emplace(i, std::move(row));
        return;
    }
    write_row(row);
    for (++next_; !waiting_.empty() && waiting_.begin()->first == next_; ++next_) {
        write_row(waiting_.begin()->second);
        waiting_.erase(waiting_.begin());
    }
}

void ManifestWriter::finish() {
    std::lock_guard lock(mutex_);
    for (const auto& [i, row] : waiting_) write_row(row);
    waiting_.clear();
    if (!file_) return;
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    const bool written = !failed_ && closed;
    const int err = written ? replace_file(temp_.c_str(), path_.c_str()) : errno;
    if (!written || err != 0) {
        ::unlink(temp_.c_str());
        throw ExportError(fmt::format("cannot write the manifest '{}': {}", path_, std::strerror(err)));
    }
}

} // namespace plant::cli
