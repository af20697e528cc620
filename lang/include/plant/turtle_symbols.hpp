// The turtle's vocabulary, one row per symbol: its name, the operation the turtle dispatches on,
// how many parameters it reads, whether it draws or is a query module, and a one-line doc (read
// by the documentation and `plant help turtle`). The symbol table registers every row
// (SymbolTable::SymbolTable), the runtime's turtle switches on the TurtleOp stored with each
// symbol (runtime/src/turtle.cpp), so adding a symbol is one row here plus its case there.
// docs/language.md, the turtle, describes the same symbols for readers.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace plant {

// What the turtle does for a module. None: nothing (a module without turtle meaning).
enum class TurtleOp : std::uint8_t {
    None,
    Forward,       // F G: move drawing a segment
    Move,          // f: move without drawing
    TurnLeft,      // +
    TurnRight,     // -
    PitchDown,     // &
    PitchUp,       // ^
    RollLeft,      // backslash
    RollRight,     // /
    TurnAround,    // |
    RollLevel,     // $
    Push,          // [
    Pop,           // ]
    Width,         // !
    PaletteColor,  // ;
    Surface,       // ~name
    Cut,           // %: handled while rewriting; the turtle ignores it
    Sphere,        // @O
    SetHeading,    // @R SetHead
    MoveTo,        // @M
    Tropism,       // @Tp
    Elasticity,    // @Ts
    RgbColor,      // SetColor
    QueryPosition, // ?P
    QueryHeading,  // ?H
    QueryUp,       // ?U
    QueryLeft,     // ?L
    Communicate,   // ?E
    SetTexture,    // SetTexture
};

enum class TurtleKind : std::uint8_t {
    Turtle, // acts on the turtle's state or draws
    Query,  // a query module: the turtle pass writes its parameters (docs/language.md, the turtle)
};

// Parameters past `max_params` are ignored; a symbol given fewer than `min_params` (when its doc
// says nothing else) takes the defaults its doc names. Nothing rejects a turtle symbol's count
// except the brackets' (they take none).
inline constexpr std::uint8_t kAnyParams = 255;

struct TurtleSymbol {
    std::string_view name;
    TurtleOp op;
    std::uint8_t min_params, max_params;
    TurtleKind kind;
    std::string_view params; // as shown in the doc: "l, w"
    std::string_view doc;
    // The row stands for every longer name that starts with `name` ("~leaf"); the bare name is
    // registered as a turtle symbol that does nothing.
    bool prefix = false;
};

// The order of rows is the order of registration, which fixes the symbols' ids: keep it, append.
inline constexpr std::array<TurtleSymbol, 30> kTurtleSymbols{{
    {"F", TurtleOp::Forward, 0, 2, TurtleKind::Turtle, "l, w",
     "move by l (default the grammar's step) drawing a segment; w sets the width first; then tropism"},
    {"f", TurtleOp::Move, 0, 1, TurtleKind::Turtle, "l",
     "move by l (default step) without drawing; the next F starts a new tube"},
    {"G", TurtleOp::Forward, 0, 2, TurtleKind::Turtle, "l, w", "the same as F"},
    {"+", TurtleOp::TurnLeft, 0, 1, TurtleKind::Turtle, "a",
     "turn H toward L by a degrees about U (default the grammar's angle)"},
    {"-", TurtleOp::TurnRight, 0, 1, TurtleKind::Turtle, "a",
     "turn H away from L by a degrees (default angle)"},
    {"&", TurtleOp::PitchDown, 0, 1, TurtleKind::Turtle, "a",
     "pitch H down toward -U by a degrees about L (default angle)"},
    {"^", TurtleOp::PitchUp, 0, 1, TurtleKind::Turtle, "a",
     "pitch H up toward U by a degrees (default angle)"},
    {"\\", TurtleOp::RollLeft, 0, 1, TurtleKind::Turtle, "a",
     "roll L away from U by a degrees about H (default angle)"},
    {"/", TurtleOp::RollRight, 0, 1, TurtleKind::Turtle, "a",
     "roll L toward U by a degrees about H (default angle)"},
    {"|", TurtleOp::TurnAround, 0, 0, TurtleKind::Turtle, "", "turn around: 180 degrees about U"},
    {"$", TurtleOp::RollLevel, 0, 0, TurtleKind::Turtle, "",
     "roll about H so that L is horizontal (unchanged when H is vertical)"},
    {"[", TurtleOp::Push, 0, 0, TurtleKind::Turtle, "", "push the turtle's state; what follows is a branch"},
    {"]", TurtleOp::Pop, 0, 0, TurtleKind::Turtle, "",
     "pop the state pushed by the matching '['; without one, a runtime error naming its place"},
    {"!", TurtleOp::Width, 0, 1, TurtleKind::Turtle, "w",
     "set the width (the tube's diameter, at least 0; starts at the grammar's width); without w, unchanged"},
    {";", TurtleOp::PaletteColor, 0, 1, TurtleKind::Turtle, "c",
     "palette color c (0 bark, 1 leaf green, 2 red, 3 yellow, ...); without c, the next one"},
    {"~", TurtleOp::Surface, 0, 1, TurtleKind::Turtle, "s",
     "~name places surface name scaled by s (default 1) in the turtle's frame (x right, y heading, z up)",
     true},
    {"%", TurtleOp::Cut, 0, 0, TurtleKind::Turtle, "",
     "cut: rewriting removes the rest of the branch; the turtle ignores it"},
    {"@O", TurtleOp::Sphere, 0, 1, TurtleKind::Turtle, "r",
     "a sphere of radius r, at least 0 (default half the width)"},
    {"@R", TurtleOp::SetHeading, 3, 6, TurtleKind::Turtle, "hx, hy, hz, ux, uy, uz",
     "set the heading (and with six numbers the up hint); fewer than three: unchanged"},
    {"SetHead", TurtleOp::SetHeading, 3, 6, TurtleKind::Turtle, "hx, hy, hz, ux, uy, uz", "the same as @R"},
    {"@M", TurtleOp::MoveTo, 3, 3, TurtleKind::Turtle, "x, y, z",
     "move to the point without drawing (fewer than three numbers: stay); the next F starts a new tube"},
    {"@Tp", TurtleOp::Tropism, 3, 3, TurtleKind::Turtle, "x, y, z",
     "tropism vector T (default 0, -1, 0): after each F, H turns toward T by e |H x T| (ABOP p. 58)"},
    {"@Ts", TurtleOp::Elasticity, 0, 1, TurtleKind::Turtle, "e",
     "tropism elasticity e (default 0: no tropism)"},
    {"SetColor", TurtleOp::RgbColor, 0, 3, TurtleKind::Turtle, "r, g, b",
     "RGB color in 0..1, or 0..255 when a component is above 1; missing components 0, clamped to 0..1"},
    {"?P", TurtleOp::QueryPosition, 3, 3, TurtleKind::Query, "x, y, z", "receives the turtle's position"},
    {"?H", TurtleOp::QueryHeading, 3, 3, TurtleKind::Query, "x, y, z", "receives the turtle's heading"},
    {"?U", TurtleOp::QueryUp, 3, 3, TurtleKind::Query, "x, y, z", "receives the turtle's up vector"},
    {"?L", TurtleOp::QueryLeft, 3, 3, TurtleKind::Query, "x, y, z", "receives the turtle's left vector"},
    {"?E", TurtleOp::Communicate, 2, kAnyParams, TurtleKind::Query, "env, slots...",
     "communication module: environment env fills the slots with its answers at this place"},
    {"SetTexture", TurtleOp::SetTexture, 0, 1, TurtleKind::Turtle, "t",
     "texture t (a name declared with `texture t = image(...)`) on what follows; -1 or no t: none"},
}};

// The row of an operation (the first, for operations two names share); nullptr for None.
constexpr const TurtleSymbol* turtle_symbol(TurtleOp op) {
    for (const TurtleSymbol& t : kTurtleSymbols)
        if (t.op == op) return &t;
    return nullptr;
}

// The operation of a symbol that no row names exactly, from the prefix rows: "~leaf" places a
// surface; None for any other name.
constexpr TurtleOp prefixed_turtle_op(std::string_view name) {
    for (const TurtleSymbol& t : kTurtleSymbols)
        if (t.prefix && name.size() > t.name.size() && name.substr(0, t.name.size()) == t.name) return t.op;
    return TurtleOp::None;
}

} // namespace plant
