#include "plant/diagnostics.hpp"

#include <catch2/catch.hpp>

using namespace plant;

TEST_CASE("line and column of byte offsets", "[source]") {
    SourceFile f("a.plant", "ab\ncde\n\nf");
    CHECK(f.line_col(0).line == 1);
    CHECK(f.line_col(0).col == 1);
    CHECK(f.line_col(4).line == 2);
    CHECK(f.line_col(4).col == 2);
    CHECK(f.line_col(8).line == 4);
    CHECK(f.line_text(2) == "cde");
    CHECK(f.line_text(3).empty());
}

TEST_CASE("a diagnostic renders file:line:col, the line and a caret under the span", "[diagnostics]") {
    SourceManager sm;
    auto id = sm.add("g.plant", "axiom: A;\nrules { A -> B }\n");
    Diagnostics ds;
    ds.error({id, 23, 24}, "expected ';' after production (started at 2:9), found '}'");
    std::string text = render_all(ds, sm);
    CHECK(text == "g.plant:2:14: error: expected ';' after production (started at 2:9), found '}'\n"
                  "    2 | rules { A -> B }\n"
                  "      |              ^\n");
}

TEST_CASE("the same diagnostic is kept once and the count is capped", "[diagnostics]") {
    SourceManager sm;
    auto id = sm.add("g.plant", "x\n");
    Diagnostics ds(3);
    ds.error({id, 0, 1}, "m");
    ds.error({id, 0, 1}, "m");
    CHECK(ds.all().size() == 1);
    for (int i = 0; i < 10; ++i) ds.error({id, 0, 1}, std::to_string(i));
    CHECK(ds.all().size() == 3);
    CHECK(ds.error_count() == 11);
}

TEST_CASE("a span over several characters gets a caret with tildes, and binary bytes are masked",
          "[diagnostics]") {
    SourceManager sm;
    auto id = sm.add("g.plant", std::string("ab\x01\x02 xyz\n"));
    Diagnostics ds;
    ds.error({id, 5, 8}, "bad");
    std::string text = render_all(ds, sm);
    CHECK(text.find("ab?? xyz") != std::string::npos);
    CHECK(text.find("     ^~~\n") != std::string::npos);
}
