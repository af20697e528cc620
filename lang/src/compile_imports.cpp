// Stage 1: files and imports. Each file is parsed, its imports are found (-I, PLANT_PATH, the
// standard library), read and loaded first, with their `with { }` overrides; `order_` ends up
// with every file after the files it imports.
#include "compiler_internal.hpp"
#include "plant/parser.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#ifndef PLANT_STDLIB_DIR
#define PLANT_STDLIB_DIR ""
#endif

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
    std::vector<std::string> dirs = opts_.include_dirs;
    if (const char* pp = std::getenv("PLANT_PATH")) {
        std::string s = pp;
        std::size_t b = 0;
        while (b <= s.size()) {
            std::size_t e = s.find(':', b);
            if (e == std::string::npos) e = s.size();
            if (e > b) dirs.push_back(s.substr(b, e - b));
            b = e + 1;
        }
    }
    if (std::string(PLANT_STDLIB_DIR).size()) dirs.emplace_back(PLANT_STDLIB_DIR);
    for (const auto& d : dirs) {
        fs::path p = fs::path(d) / (im.target + ".plant");
        searched.push_back(p.string());
        if (fs::exists(p, ec)) return p.lexically_normal().string();
    }
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
    std::string self = fs::path(sm_.file(file_id).name()).lexically_normal().string();
    stack.push_back(self);
    loaded_paths_.insert(self);
    for (const auto& im : f->imports) {
        std::vector<std::string> searched;
        std::string path = resolve_import(im, file_id, searched);
        if (path.empty()) {
            diags_->error(im.span, im.is_path ? fmt::format("cannot find imported file '{}' (looked for {})",
                                                            im.target, searched.empty() ? "?" : searched[0])
                                              : fmt::format("cannot find library '{}' (searched {})",
                                                            im.target, fmt::join(searched, ", ")));
            continue;
        }
        if (std::find(stack.begin(), stack.end(), path) != stack.end()) {
            diags_->error(im.span,
                          fmt::format("import cycle: '{}' imports '{}', which is already being imported "
                                      "(chain: {})",
                                      self, path, fmt::join(stack, " -> ")));
            continue;
        }
        if (loaded_paths_.count(path)) continue; // imported already through another path
        if (stack.size() >= kMaxImportDepth) {   // load() recurses once per file of the chain
            diags_->error(im.span,
                          fmt::format("imports nested deeper than {} files (the chain starts at '{}'); "
                                      "import the libraries side by side instead",
                                      kMaxImportDepth, stack.front()));
            continue;
        }
        std::string text;
        if (auto it = opts_.file_texts.find(path); it != opts_.file_texts.end()) {
            text = it->second;
        } else if (!read_file(path, text)) {
            diags_->error(im.span, fmt::format("cannot read imported file '{}'", path));
            continue;
        }
        std::uint32_t id = sm_.add(path, std::move(text));
        std::map<std::string, std::pair<const ast::Expr*, Span>> ov;
        for (std::size_t k = 0; k < im.overrides.size(); ++k) {
            const std::string& name = im.overrides[k].first;
            if (auto it = ov.find(name); it != ov.end()) {
                duplicate("override", name, im.override_spans[k], it->second.second);
                continue;
            }
            ov[name] = {im.overrides[k].second.get(), im.override_spans[k]};
        }
        load(id, std::move(ov), stack);
    }
    stack.pop_back();
    order_.push_back({f, std::move(overrides)});
}

} // namespace plant
