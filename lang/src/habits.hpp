// Forms that ABOP, cpfg and L-Py users type from habit and that plant reads differently or not
// at all: the parser's hints that name what to write instead, and the cpfg preprocessor lines
// that '#' would otherwise turn into comments (docs/language.md, coming from ABOP, cpfg or L-Py).
#pragma once

#include "plant/diagnostics.hpp"
#include "plant/source.hpp"

#include <string>
#include <string_view>

namespace plant::habits {

// For a parse error `message` at `byte` of `text`: a sentence that names the plant form of what
// the user probably meant ("; write ..."), or an empty string.
std::string hint(const std::string& text, std::size_t byte, const std::string& message);

// A letter run that reads like a word meant as one module (`leaf`, `plant`): three or more
// lower-case letters, with a vowel and a consonant, or a capital and three or more such letters
// (`Leaf`; docs/language.md, coming from ABOP, cpfg or L-Py). FbFb, Xab, Bud, ff and ab do not.
bool looks_like_a_name(std::string_view run);

// cpfg's preprocessor lines (#define, #ignore:, #consider:, #include) are comments in plant: each
// is an error at its line naming the plant item to write.
void check_cpfg_lines(const SourceFile& src, std::uint32_t file_id, Diagnostics& diags);

} // namespace plant::habits
