// SPDX-License-Identifier: GPL-3.0-or-later
// [questions] of a protocol file: the surface question, the scales, the soundscape question.
#include "experiment/ProtocolReader.h"

namespace underfoot::experiment::protocol_detail {

namespace {

std::vector<AnswerOption> readOptions(Reader& r, const toml::table& t, std::string_view context,
                                      bool surfaces, const Catalogue& catalogue) {
    std::vector<AnswerOption> options;
    const auto ids = r.strings(t, "options", context);
    if (ids.empty() && t.get("options") && t.get("options")->is_array())
        r.problem(*t.get("options"), fmt::format("'options' in {} is empty", context));
    if (!t.get("options"))
        r.problem(t, fmt::format("missing key 'options' in {}; expected an array of {} ids",
                                 context, surfaces ? "surface" : "soundscape"));
    std::set<std::string> seen;
    for (const auto& [optionId, where] : ids) {
        const CatalogueEntry* entry =
            surfaces ? catalogue.surface(optionId) : catalogue.soundscape(optionId);
        if (!entry && !(optionId == kDontKnow)) {
            r.problem(where,
                      fmt::format("unknown {} '{}' in {}.options; expected one of: {}{}",
                                  surfaces ? "surface" : "soundscape", optionId, context,
                                  joinIds(surfaces ? catalogue.surfaces : catalogue.soundscapes),
                                  ", dont_know"));
            continue;
        }
        if (!seen.insert(optionId).second) {
            r.problem(where, fmt::format("'{}' appears twice in {}.options", optionId, context));
            continue;
        }
        options.push_back({optionId, '?', entry ? entry->label : "I don't know"});
    }
    const bool dontKnow = r.boolean(t, "dont_know", context).value_or(true);
    if (dontKnow && !seen.count(std::string(kDontKnow)))
        options.push_back({std::string(kDontKnow), '?', "I don't know"});
    if (options.size() > 26)
        r.problem(t, fmt::format("{} has {} options; at most 26 fit the keyboard letters a-z",
                                 context, options.size()));
    for (std::size_t i = 0; i < options.size() && i < 26; ++i)
        options[i].letter = static_cast<char>('a' + i);
    // Optional relabelling: labels = { deep_snow = "snow" }.
    if (auto labels = r.table(t, "labels", context, false)) {
        for (auto&& [key, node] : *labels) {
            const std::string_view keyName = key.str(); // clang 14 cannot capture a binding
            auto it = std::find_if(options.begin(), options.end(),
                                   [&](const AnswerOption& o) { return o.id == keyName; });
            if (it == options.end())
                r.problem(node, fmt::format("label for '{}' in {}.labels, which is not an option",
                                            key.str(), context));
            else if (!node.is_string())
                r.problem(node, fmt::format("labels in {}.labels must be strings", context));
            else
                it->label = node.as_string()->get();
        }
    }
    return options;
}

} // namespace

void readQuestions(ProtocolParse& x) {
    Reader& r = x.r;
    const toml::table& root = x.root;
    Protocol& p = x.p;
    const Catalogue& catalogue = x.catalogue;
    const toml::table* orderingTable = x.orderingTable;
    // [questions]
    if (auto t = r.table(root, "questions", "the protocol file", true)) {
        r.checkKeys(*t, {"surface", "scales", "soundscape", "comment"}, "[questions]");
        p.questions.comment = r.boolean(*t, "comment", "[questions]").value_or(false);
        if (auto s = r.table(*t, "surface", "[questions]", false)) {
            r.checkKeys(*s, {"prompt", "options", "dont_know", "labels"}, "[questions.surface]");
            p.questions.surfacePrompt = r.string(*s, "prompt", "[questions.surface]", false)
                                            .value_or("Which surface are you walking on?");
            const std::size_t before = r.problems().size();
            p.questions.surfaceOptions = readOptions(r, *s, "[questions.surface]", true, catalogue);
            // With a broken option list, every stimulus seems unanswerable: that follows from it.
            const bool optionsBroken = r.problems().size() > before;
            // Every stimulus must be answerable correctly.
            for (const auto& st : p.stimuli) {
                if (st.surface.empty() || !catalogue.surface(st.surface)) continue;
                bool answerable = false;
                for (const auto& o : p.questions.surfaceOptions)
                    answerable = answerable || answerIsCorrect(o.id, st.surface);
                if (!answerable) {
                    const std::string message = fmt::format(
                        "no answer option names the surface of stimulus '{}' ('{}'); expected "
                        "'{}' in [questions.surface].options",
                        st.id, st.surface, baseSurface(st.surface));
                    if (optionsBroken)
                        r.derived(s->source(), message);
                    else
                        r.problem(*s, message);
                }
            }
        }
        if (const toml::node* scalesNode = t->get("scales")) {
            if (!scalesNode->is_array_of_tables())
                r.problem(*scalesNode,
                          "'scales' must be an array of tables ([[questions.scales]])");
            else
                for (const toml::node& element : *scalesNode->as_array()) {
                    const toml::table& st = *element.as_table();
                    const std::string ctx =
                        fmt::format("[[questions.scales]] #{}", p.questions.scales.size() + 1);
                    r.checkKeys(st,
                                {"id", "prompt", "min", "max", "min_label", "max_label", "anchors",
                                 "stimuli"},
                                ctx);
                    Scale sc;
                    sc.id = r.id(st, "id", ctx, true).value_or("");
                    sc.prompt = r.string(st, "prompt", ctx, true).value_or("");
                    sc.min =
                        static_cast<int>(r.integer(st, "min", ctx, true, -1000, 1000).value_or(1));
                    sc.max =
                        static_cast<int>(r.integer(st, "max", ctx, true, -1000, 1000).value_or(7));
                    sc.minLabel = r.string(st, "min_label", ctx, false).value_or("");
                    sc.maxLabel = r.string(st, "max_label", ctx, false).value_or("");
                    if (sc.min >= sc.max)
                        r.problem(st, fmt::format("scale '{}' has min {} >= max {}; expected "
                                                  "min < max",
                                                  sc.id, sc.min, sc.max));
                    if (auto anchors = r.table(st, "anchors", ctx, false)) {
                        for (auto&& [key, node] : *anchors) {
                            const std::string k(key.str());
                            int value = 0;
                            std::size_t used = 0;
                            bool isNumber = !k.empty();
                            try {
                                value = std::stoi(k, &used);
                            } catch (const std::exception&) {
                                isNumber = false;
                            }
                            const auto& where =
                                key.source().begin.line ? key.source() : node.source();
                            if (!isNumber || used != k.size())
                                r.problem(where, fmt::format("anchor '{}' of scale '{}' is not a "
                                                             "whole number; expected a scale "
                                                             "point such as {} = \"...\"",
                                                             k, sc.id, sc.min));
                            else if (value < sc.min || value > sc.max)
                                r.problem(where, fmt::format("anchor {} of scale '{}' is outside "
                                                             "its range; expected {} to {}",
                                                             value, sc.id, sc.min, sc.max));
                            else if (!node.is_string() || node.as_string()->get().empty())
                                r.problem(node, fmt::format("anchor {} of scale '{}' must be a "
                                                            "non-empty string",
                                                            value, sc.id));
                            else
                                sc.anchors[value] = node.as_string()->get();
                        }
                        if (sc.minLabel.empty() && sc.anchors.count(sc.min))
                            sc.minLabel = sc.anchors[sc.min];
                        if (sc.maxLabel.empty() && sc.anchors.count(sc.max))
                            sc.maxLabel = sc.anchors[sc.max];
                    }
                    if (!sc.minLabel.empty()) sc.anchors.try_emplace(sc.min, sc.minLabel);
                    if (!sc.maxLabel.empty()) sc.anchors.try_emplace(sc.max, sc.maxLabel);
                    for (const auto& [sid, where] : r.strings(st, "stimuli", ctx)) {
                        const Stimulus* target = p.stimulus(sid);
                        if (!target)
                            r.problem(where, fmt::format("scale '{}' names unknown stimulus "
                                                         "'{}'; expected one of the stimulus ids",
                                                         sc.id, sid));
                        else if (std::find(sc.stimuli.begin(), sc.stimuli.end(), sid) !=
                                 sc.stimuli.end())
                            r.problem(where, fmt::format("scale '{}' lists stimulus '{}' twice",
                                                         sc.id, sid));
                        else
                            sc.stimuli.push_back(sid);
                    }
                    if (st.get("stimuli") && sc.stimuli.empty() && st.get("stimuli")->is_array())
                        r.problem(*st.get("stimuli"),
                                  fmt::format("scale '{}' has an empty 'stimuli' list; expected "
                                              "stimulus ids, or no list for every stimulus",
                                              sc.id));
                    if (!sc.id.empty() && p.questions.scale(sc.id))
                        r.problem(st, fmt::format("scale id '{}' is used twice", sc.id));
                    else
                        p.questions.scales.push_back(sc);
                }
        }
        if (auto s = r.table(*t, "soundscape", "[questions]", false)) {
            r.checkKeys(*s, {"prompt", "options", "dont_know", "labels", "groups"},
                        "[questions.soundscape]");
            p.questions.soundscapePrompt = r.string(*s, "prompt", "[questions.soundscape]", false)
                                               .value_or("Which environment are you in?");
            p.questions.soundscapeOptions =
                readOptions(r, *s, "[questions.soundscape]", false, catalogue);
            for (const auto& [gid, where] : r.strings(*s, "groups", "[questions.soundscape]")) {
                if (!p.group(gid))
                    r.problem(where, fmt::format("[questions.soundscape] names unknown group "
                                                 "'{}'; expected one of: {}",
                                                 gid, [&] {
                                                     std::vector<std::string> ids;
                                                     for (const auto& g : p.groups)
                                                         ids.push_back(g.id);
                                                     return joinList(ids);
                                                 }()));
                else
                    p.questions.soundscapeGroups.push_back(gid);
            }
        }
        if (!p.questions.asksSurface() && p.questions.scales.empty() &&
            p.questions.soundscapeOptions.empty())
            r.derived(t->source(), "[questions] asks nothing; expected a surface question, "
                                   "scales or a soundscape question");
    }

    if (p.ordering.blocks == BlockKind::Scale && p.questions.scales.empty())
        r.problem(orderingTable ? orderingTable->source() : root.source(),
                  "blocks = \"scale\" needs [[questions.scales]]; expected at least one scale");
    if (p.ordering.blocks == BlockKind::Scale && p.questions.asksSurface())
        r.problem(orderingTable ? orderingTable->source() : root.source(),
                  "blocks = \"scale\" asks one scale per block; the surface question would be "
                  "asked in every block — remove [questions.surface] or the scale blocks");
    checkOrdering(r, orderingTable, root, p);
}

} // namespace underfoot::experiment::protocol_detail
