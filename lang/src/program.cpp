// The compiled program's own lookups: the symbol table (turtle and query symbols are interned
// first, so their ids are fixed), the rule index by first symbol, rule groups by name.
#include "plant/program.hpp"

#include <cctype>

namespace plant {

SymbolTable::SymbolTable() {
    // the turtle's symbols and query modules, one row each in plant/turtle_symbols.hpp
    for (const TurtleSymbol& t : kTurtleSymbols) {
        SymbolId id = intern(t.name);
        SymbolInfo& info = infos_[id];
        if (!t.prefix) info.turtle_op = t.op;
        info.turtle = t.kind == TurtleKind::Turtle;
        info.query = t.kind == TurtleKind::Query;
        // multi-letter turtle names are declared so letter runs do not split them
        info.declared =
            info.query || (t.name.size() > 1 && std::isalpha(static_cast<unsigned char>(t.name[0])));
    }
    auto by_op = [&](TurtleOp op) { return *find(turtle_symbol(op)->name); };
    open_bracket = by_op(TurtleOp::Push);
    close_bracket = by_op(TurtleOp::Pop);
    cut = by_op(TurtleOp::Cut);
}

SymbolId SymbolTable::intern(std::string_view name) {
    auto it = index_.find(std::string(name));
    if (it != index_.end()) return it->second;
    if (infos_.size() >= kNoSymbol) throw Full{};
    auto id = static_cast<SymbolId>(infos_.size());
    SymbolInfo info;
    info.name = std::string(name);
    info.turtle_op = prefixed_turtle_op(name);
    infos_.push_back(std::move(info));
    index_.emplace(std::string(name), id);
    return id;
}

std::optional<SymbolId> SymbolTable::find(std::string_view name) const {
    auto it = index_.find(std::string(name));
    if (it == index_.end()) return std::nullopt;
    return it->second;
}

void RuleSet::index(std::size_t symbols) {
    by_symbol.assign(symbols, {});
    for (std::uint32_t i = 0; i < productions.size(); ++i)
        by_symbol[productions[i].strict[0].sym].push_back(i);
}

int Program::group_index(std::string_view name) const {
    for (std::size_t i = 0; i < groups.size(); ++i)
        if (groups[i].name == name) return static_cast<int>(i);
    return -1;
}

} // namespace plant
