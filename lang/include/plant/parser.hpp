// Parsing .plant source into the syntax tree. Errors are added to the diagnostics; the parser
// recovers at the next top-level item so one run reports several independent mistakes.
#pragma once

#include "plant/ast.hpp"
#include "plant/diagnostics.hpp"

namespace plant {

std::unique_ptr<ast::File> parse_file(const SourceManager& sources, std::uint32_t file_id,
                                      Diagnostics& diags);

// Parses one expression (the REPL and -D values use it). Returns null on error.
ast::ExprPtr parse_expression(const SourceManager& sources, std::uint32_t file_id, Diagnostics& diags);
// Parses the bytes [begin, end) of a file as one expression (a value in an edits file), with
// positions in the whole file. Returns null on error.
ast::ExprPtr parse_expression(const SourceManager& sources, std::uint32_t file_id, std::uint32_t begin,
                              std::uint32_t end, Diagnostics& diags);

} // namespace plant
