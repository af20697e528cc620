#include "man_page.hpp"
#include "version.hpp"

#include <fmt/format.h>

#include <sstream>

namespace plant::cli {

namespace {

// Text as troff prints it: backslashes and minus signs escaped, and a line that starts with a
// control character ('.' or '\'') guarded so that it is not read as a request.
std::string escape(const std::string& text) {
    std::string out;
    bool line_start = true;
    for (char c : text) {
        if (line_start && (c == '.' || c == '\'')) out += "\\&";
        if (c == '\\')
            out += "\\e";
        else if (c == '-')
            out += "\\-";
        else
            out += c;
        line_start = c == '\n';
    }
    return out;
}

// A block printed as it is, lines and spacing kept (a command's --help).
std::string verbatim(const std::string& text) {
    std::string body = escape(text);
    if (!body.empty() && body.back() != '\n') body += '\n';
    // an empty line in no-fill mode is kept, but `.sp` says so without relying on it
    std::string out;
    std::istringstream lines(body);
    for (std::string line; std::getline(lines, line);) out += line.empty() ? ".sp\n" : line + "\n";
    return ".PP\n.nf\n" + out + ".fi\n";
}

const char* const kFiles = R"(.TP
.I PREFIX/share/plant/stdlib/
The standard library, found beside the program (\fIPREFIX\fR/bin/plant reads
\fIPREFIX\fR/share/plant/stdlib), so a moved install keeps working. A program run from the
build folder it was built in reads the source tree's \fIstdlib/\fR instead.
.TP
.I PREFIX/share/doc/plant/
The documentation: README.md, language.md (the language), install.md (installing, packaging and
the C++ API) and the others.
)";

const char* const kEnvironment = R"(.TP
.B PLANT_PATH
Folders separated by colons, searched for \fBimport\fR \fIname\fR\fB;\fR after the \fB\-I\fR
folders and before the standard library.
)";

const char* const kExitStatus = R"(.TP
.B 0
success
.TP
.B 1
a test failed (plant test), or a command of a script piped into plant repl did
.TP
.B 64
usage error
.TP
.B 65
the grammar has errors
.TP
.B 66
an input cannot be read
.TP
.B 70
runtime error (a derivation or export failed)
.TP
.B 73
an output file cannot be created
)";

} // namespace

std::string man_page(CLI::App& app, const std::vector<std::pair<std::string, std::string>>& topics) {
    std::string out = fmt::format(".TH PLANT 1 \"\" \"plant {}\" \"User Commands\"\n", escape(kVersion));
    out += ".SH NAME\nplant \\- grow plants from parametric L\\-system grammars\n";
    out += ".SH SYNOPSIS\n.B plant\n.I COMMAND\n[\\fIOPTIONS\\fR] [\\fIFILE\\fR]\n.br\n";
    out += ".B plant \\-\\-version\n.br\n.B plant help\n[\\fITOPIC\\fR]\n";
    out += ".SH DESCRIPTION\n" + verbatim(app.get_description());
    out += ".SH COMMANDS\n";
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
        out += fmt::format(".SS \"plant {}\"\n",
                           escape(sub->get_name())); // its help starts with the description
        out += verbatim(sub->help("plant"));
    }
    out += ".SH HELP TOPICS\n\\fBplant help\\fR \\fITOPIC\\fR prints one of these tables:\n";
    for (const auto& [name, summary] : topics)
        out += fmt::format(".TP\n.B {}\n{}\n", escape(name), escape(summary));
    out += std::string(".SH FILES\n") + kFiles;
    out += std::string(".SH ENVIRONMENT\n") + kEnvironment;
    out += std::string(".SH EXIT STATUS\n") + kExitStatus;
    out += ".SH SEE ALSO\nThe documents in \\fIPREFIX\\fR/share/doc/plant/.\n";
    return out;
}

} // namespace plant::cli
