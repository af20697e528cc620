// Stage 1: files and imports. Each file is parsed, its imports are found (-I, PLANT_PATH, the
// standard library), read and loaded first, with their `with { }` overrides; `order_` ends up
// with every file after the files it imports.
#include "compiler_internal.hpp"
#include "plant/parser.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

namespace plant {

namespace fs = std::filesystem;

namespace {
constexpr std::size_t kMaxImportDepth = 64; // files open at once in a chain of imports
} // namespace

std::string Compiler::resolve_import(const ast::Import& im, std::uint32_t from_file,
                                     std::vector<std::string>& searched) {
    fs::path from_dir = fs::path(sm_.file(from_file).name()).parent_path();
    std::error_code ec;
    if (im.is_path) {
        fs::path p = fs::path(im.target).is_absolute() ? fs::path(im.target) : from_dir / im.target;
        if (opts_.file_texts.count(p.lexically_normal().string())) return p.lexically_normal().string();
        searched.push_back(p.string());
        return fs::exists(p, ec) ? p.lexically_normal().string() : std::string();
    }
    std::vector<std::string> dirs = library_dirs(opts_);
    for (const auto& d : dirs) {
        fs::path p = fs::path(d) / (im.target + ".plant");
        searched.push_back(p.string());
        if (fs::exists(p, ec)) return p.lexically_normal().string();
    }
    return {};
}

std::string Compiler::readable(const std::string& written, const std::string& path, Span span) {
    if (!access_) access_ = std::make_unique<FileAccess>(sm_.file(main_file_).name(), opts_);
    std::string id = FileAccess::identity(path);
    if (id.empty()) return path; // missing: whoever reads it says so
    if (!opts_.confine_reads || access_->allowed(id)) return id;
    diags_->input_error(span, FileAccess::refusal(written));
    return {};
}

void Compiler::load(std::uint32_t file_id, std::map<std::string, std::pair<const ast::Expr*, Span>> overrides,
                    std::vector<std::string>& stack) {
    auto file = parse_file(sm_, file_id, *diags_);
    ast::File* f = file.get();
    ProgramFile& outline = P_.files.emplace_back();
    outline.source = file_id;
    for (const auto& rb : f->rule_blocks) {
        RuleBlockSource& block = outline.rule_blocks.emplace_back();
        block.kind = rb.kind;
        block.group = rb.group;
        for (const auto& p : rb.productions) block.productions.push_back(p.span);
    }
    files_.push_back(std::move(file));
    // files are told apart by identity (symbolic links and `..` resolved), shown as named
    const std::string self_shown = fs::path(sm_.file(file_id).name()).lexically_normal().string();
    std::string self = FileAccess::identity(self_shown);
    if (self.empty()) self = self_shown;
    shown_[self] = self_shown;
    stack.push_back(self);
    loaded_paths_.insert(self);
    for (const auto& im : f->imports) {
        std::vector<std::string> searched;
        std::string path = resolve_import(im, file_id, searched);
        if (path.empty()) {
            diags_->input_error(im.span, im.is_path
                                             ? fmt::format("cannot find imported file '{}' (looked for {})",
                                                           im.target, searched.empty() ? "?" : searched[0])
                                             : fmt::format("cannot find library '{}' (searched {})",
                                                           im.target, fmt::join(searched, ", ")));
            continue;
        }
        const auto given = opts_.file_texts.find(path);
        std::string id = path;
        if (given == opts_.file_texts.end()) {
            id = readable(im.target, path, im.span);
            if (id.empty()) continue;
        } else if (std::string c = FileAccess::identity(path); !c.empty()) {
            id = c;
        }
        if (std::find(stack.begin(), stack.end(), id) != stack.end()) {
            std::vector<std::string> chain;
            for (const auto& s : stack) chain.push_back(shown_[s]);
            diags_->error(im.span,
                          fmt::format("import cycle: '{}' imports '{}', which is already being imported "
                                      "(chain: {})",
                                      self_shown, path, fmt::join(chain, " -> ")));
            continue;
        }
        if (loaded_paths_.count(id)) continue; // imported already through another path
        if (stack.size() >= kMaxImportDepth) { // load() recurses once per file of the chain
            diags_->error(im.span,
                          fmt::format("imports nested deeper than {} files (the chain starts at '{}'); "
                                      "import the libraries side by side instead",
                                      kMaxImportDepth, shown_[stack.front()]));
            continue;
        }
        std::string text;
        if (given != opts_.file_texts.end()) {
            text = given->second;
        } else if (ReadFailure why = read_input_file(id, text); why != ReadFailure::None) {
            diags_->input_error(im.span,
                                fmt::format("cannot read imported file '{}': {}", im.target, describe(why)));
            continue;
        }
        std::uint32_t source = sm_.add(path, std::move(text));
        std::map<std::string, std::pair<const ast::Expr*, Span>> ov;
        for (std::size_t k = 0; k < im.overrides.size(); ++k) {
            const std::string& name = im.overrides[k].first;
            if (auto it = ov.find(name); it != ov.end()) {
                duplicate("override", name, im.override_spans[k], it->second.second);
                continue;
            }
            ov[name] = {im.overrides[k].second.get(), im.override_spans[k]};
        }
        load(source, std::move(ov), stack);
    }
    stack.pop_back();
    order_.push_back({f, std::move(overrides)});
}

} // namespace plant
