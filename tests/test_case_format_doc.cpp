// docs/case-format.md against the parser: every key the parser looks up (in the built-in
// cases and in the page's own examples) is documented in one of its tables, every obstacle
// and excitation type the parser accepts has an example, and every example runs.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseExport.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/run/StringsRun.hpp"

namespace fretbuzz {
namespace {

struct Example {
    std::string kind;  // case, obstacle, excitation
    std::string text;
};

std::string read_doc() {
    std::ifstream in(std::string(FRETBUZZ_SOURCE_DIR) + "/docs/case-format.md");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// The ```toml blocks that follow an <!-- example: KIND --> marker.
std::vector<Example> examples(const std::string& doc) {
    std::vector<Example> found;
    const std::regex block(R"(<!-- example: (\w+) -->\s*```toml\n([\s\S]*?)```)");
    for (auto it = std::sregex_iterator(doc.begin(), doc.end(), block); it != std::sregex_iterator(); ++it)
        found.push_back({(*it)[1].str(), (*it)[2].str()});
    return found;
}

// Keys named in the first column of the page's tables: | `string.L` | ...
std::set<std::string> documented_keys(const std::string& doc) {
    std::set<std::string> keys;
    const std::regex row(R"(\n\| `([A-Za-z0-9_.]+)` \|)");
    for (auto it = std::sregex_iterator(doc.begin(), doc.end(), row); it != std::sregex_iterator(); ++it)
        keys.insert((*it)[1].str());
    return keys;
}

// The words a parser message offers after "must be one of".
std::vector<std::string> offered(const std::string& message) {
    std::vector<std::string> words;
    const std::string tail = message.substr(message.find("must be one of"));
    const std::regex quoted("\"([a-z-]+)\"");
    for (auto it = std::sregex_iterator(tail.begin(), tail.end(), quoted); it != std::sregex_iterator(); ++it)
        words.push_back((*it)[1].str());
    return words;
}

// The string, damping, contact, run and observation a fragment example is completed with.
const std::string kBase = R"(name = "doc-example"
[string]
L = 1.0
T = 150.0
mu = 1.5e-3
modes = 120
ideal = true
[modes.damping]
model = "law"
eta0 = 0.5
eta2 = 1e-4
[contact]
K = 5e11
alpha = 1.5
[run]
fs = 200000
duration = 0.002
[observe]
x = [0.7]
)";
const std::string kRestingExcitation = "[excitation]\ntype = \"sine\"\nmode = 1\namplitude = 5e-4\n";
const std::string kNoObstacle = "[obstacle]\ntype = \"none\"\n";

std::string complete(const Example& e) {
    if (e.kind == "obstacle") return kBase + kRestingExcitation + e.text;
    if (e.kind == "excitation") return kBase + kNoObstacle + e.text;
    return e.text;
}

// The data files the fragment examples name.
void write_example_files(const std::filesystem::path& dir) {
    std::ofstream(dir / "my_obstacle.csv") << "# x_m,height_m\n0,-1e-3\n1,-1.5e-3\n";
    std::ofstream(dir / "my_modal.csv") << "# mode,q\n1,1e-4\n3,-2e-5\n";
    std::ofstream(dir / "my_shape.csv") << "# x_m,u_m\n0,0\n0.3,5e-4\n1,0\n";
}

class CaseFormatDoc : public ::testing::Test {
protected:
    void SetUp() override {
        doc_ = read_doc();
        ASSERT_FALSE(doc_.empty()) << "docs/case-format.md not found";
        examples_ = examples(doc_);
        documented_ = documented_keys(doc_);
        write_example_files(dir_.path());
    }
    std::string message_for(const std::string& text) const {
        try {
            parse_case(text, "probe.toml", DataSource::directory(dir_.path()));
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    }
    std::string doc_;
    std::vector<Example> examples_;
    std::set<std::string> documented_;
    testing::ScratchDir dir_{"case-doc"};
};

TEST_F(CaseFormatDoc, EveryKeyTheParserReadsIsDocumented) {
    std::vector<std::pair<std::string, std::string>> corpus;  // (where, text)
    for (const auto& info : builtin_cases()) corpus.emplace_back("built-in case " + info.name, builtin_case_text(info.name));
    for (const Example& e : examples_) corpus.emplace_back(e.kind + " example:\n" + e.text, complete(e));
    std::set<std::string> read;
    for (const auto& [where, text] : corpus) {
        const bool builtin = where.starts_with("built-in");
        const DataSource data = builtin ? DataSource::builtin() : DataSource::directory(dir_.path());
        std::set<std::string> keys;
        ASSERT_NO_THROW(keys = case_keys_looked_up(text, "doc.toml", data)) << where;
        read.insert(keys.begin(), keys.end());
    }
    ASSERT_GT(read.size(), 40u);
    for (const std::string& key : read)
        EXPECT_TRUE(documented_.contains(key))
            << "case-file key `" << key << "` is read by the parser but has no row in docs/case-format.md";
    // And the page documents nothing the parser never looks for.
    for (const std::string& key : documented_)
        EXPECT_TRUE(read.contains(key)) << "docs/case-format.md documents `" << key << "`, which the parser never reads";
}

TEST_F(CaseFormatDoc, EveryObstacleAndExcitationTypeHasARunningExample) {
    const std::string probe_obstacle = message_for(kBase + kRestingExcitation + "[obstacle]\ntype = \"?\"\n");
    const std::string probe_excitation = message_for(kBase + kNoObstacle + "[excitation]\ntype = \"?\"\n");
    for (const auto& [kind, message] : {std::pair{std::string("obstacle"), probe_obstacle},
                                        std::pair{std::string("excitation"), probe_excitation}}) {
        const std::vector<std::string> types = offered(message);
        ASSERT_GE(types.size(), 5u) << message;
        for (const std::string& type : types) {
            bool shown = false;
            for (const Example& e : examples_)
                shown = shown || (e.kind == kind && e.text.find("type = \"" + type + "\"") != std::string::npos);
            EXPECT_TRUE(shown) << kind << ".type = \"" << type << "\" has no example in docs/case-format.md";
        }
    }
    // Every example parses and runs (2 ms), and its result is a real motion.
    for (const Example& e : examples_) {
        if (e.kind == "strings") {  // strings on a bridge: their own kind of case
            StringsCase sc = parse_strings_case({e.text, "doc.toml", DataSource::directory(dir_.path())});
            sc.run.duration_s = 0.002;
            const StringsRun run = simulate_strings(sc);
            EXPECT_GT(run.energy.front().front(), 0.0) << e.text;
            EXPECT_LE(run.max_relative_balance_error, 1e-9) << e.text;
            continue;
        }
        const Case c = parse_case(complete(e), "doc.toml", DataSource::directory(dir_.path()));
        Case shortened = c;
        shortened.run.duration_s = 0.002;
        const RunSummary s = simulate(shortened, {});
        EXPECT_GT(s.energy_initial_j, 0.0) << e.text;
        EXPECT_LE(s.max_relative_balance_error, 1e-9) << e.text;
    }
}

TEST_F(CaseFormatDoc, EveryModelNameTheParserAcceptsIsDocumented) {
    // A string with only the model section under test.
    const auto probe = [this](const std::string& string_extra, const std::string& section) {
        return message_for("name = \"m\"\n[string]\nL = 1.0\nT = 200.0\nmu = 1e-3\nmodes = 10\n" + string_extra +
                           "[modes." + section + "]\nmodel = \"?\"\n");
    };
    const std::string frequency = probe("", "frequency");
    const std::string damping = probe("ideal = true\n", "damping");
    for (const std::string& message : {frequency, damping})
        for (const std::string& model : offered(message))
            EXPECT_NE(doc_.find("`\"" + model + "\"`"), std::string::npos) << "model \"" << model << "\" undocumented";
}

}  // namespace
}  // namespace fretbuzz
