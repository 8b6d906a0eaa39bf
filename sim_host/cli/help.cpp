// The help of every command, made from its CLI11 options, `vines help`, and
// how a parse error is reported.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "sim_host/cli/cli.hpp"

namespace vines::cli {
namespace {

constexpr std::size_t kWidth = 96;  // help text wraps here

// Words of `text` from column `indent` (the first line from `first`, already
// written), wrapped at kWidth; a '\n' in the text starts a new line.
std::string wrap(const std::string& text, std::size_t indent, std::size_t first) {
  std::string out;
  std::size_t col = first;
  std::istringstream lines(text);
  bool first_line = true;
  for (std::string line; std::getline(lines, line); first_line = false) {
    if (!first_line) out += "\n" + std::string(indent, ' '), col = indent;
    std::istringstream words(line);
    bool line_start = true;
    for (std::string w; words >> w; line_start = false) {
      if (!line_start && col + 1 + w.size() > kWidth) out += "\n" + std::string(indent, ' '), col = indent;
      else if (!line_start) out += ' ', ++col;
      out += w;
      col += w.size();
    }
  }
  return out;
}

const std::string kMainGroup = "Options";  // CLI11's default group

bool listed(const CLI::App* app, const CLI::Option* o) { return o != app->get_help_ptr(); }

// The option groups but the main one, in the order of their first option.
std::vector<std::string> other_groups(const CLI::App* app) {
  std::vector<std::string> groups;
  for (const CLI::Option* o : app->get_options())
    if (listed(app, o) && o->get_group() != kMainGroup &&
        std::find(groups.begin(), groups.end(), o->get_group()) == groups.end())
      groups.push_back(o->get_group());
  return groups;
}

// An argument as the help names it: "SCENE.toml", "--out DIR", "--realtime | --virtual-clock".
std::string label(const CLI::Option* o) {
  if (o->get_positional() && !o->nonpositional()) return o->get_name();
  std::string s;
  for (const std::string& n : o->get_lnames()) s += (s.empty() ? "--" : " | --") + n;
  const std::string type = o->get_type_name();  // the name given (none for a flag), ":", checks' descriptions
  if (!type.empty() && type[0] != ':') s += " " + type.substr(0, type.find(':'));
  return s;
}

// The arguments after `vines NAME` in the usage line: positionals, the options
// of the main group, then "[GROUP]" for each other group.
std::string synopsis(const CLI::App* app) {
  std::vector<std::string> items;
  for (const CLI::Option* o : app->get_options()) {
    if (!listed(app, o) || o->get_group() != kMainGroup) continue;
    std::string item = label(o);
    if (o->get_positional() && o->get_items_expected_max() > 1) item += "...";
    items.push_back(o->get_required() ? item : "[" + item + "]");
  }
  for (const std::string& g : other_groups(app)) items.push_back("[" + g + "]");
  std::string s;
  for (const std::string& i : items) s += (s.empty() ? "" : " ") + i;
  return s;
}

// The synopsis wrapped as wrap() does, never inside an item ("[--out DIR]").
std::string wrapped_synopsis(const CLI::App* app, std::size_t indent, std::size_t first) {
  std::string s = synopsis(app);
  for (std::size_t open = 0; (open = s.find('[', open)) != std::string::npos;)
    for (const std::size_t close = s.find(']', open); ++open < close;)
      if (s[open] == ' ') s[open] = '\x01';
  s = wrap(s, indent, first);
  std::replace(s.begin(), s.end(), '\x01', ' ');
  return s;
}

// The column of the options' descriptions: after the longest name (up to a limit).
std::size_t description_column(const CLI::App* app) {
  std::size_t longest = 0;
  for (const CLI::Option* o : app->get_options())
    if (listed(app, o) && label(o).size() <= 22) longest = std::max(longest, label(o).size());
  return 2 + longest + 2;
}

// One line per option of a group, descriptions wrapped in their column.
std::string option_lines(const CLI::App* app, const std::string& group) {
  const std::size_t column = description_column(app);
  std::string out;
  for (const CLI::Option* o : app->get_options()) {
    if (!listed(app, o) || o->get_group() != group) continue;
    const std::string name = "  " + label(o);
    out += name;
    if (name.size() + 2 > column) out += "\n" + std::string(column, ' ');
    else out += std::string(column - name.size(), ' ');
    out += wrap(o->get_description(), column, column) + "\n";
  }
  return out;
}

// `vines help`: the commands, each with its usage and summary.
std::string vines_help(const CLI::App* vines) {
  std::string out = vines->get_description() + "\n\nusage: vines <command> [options]\n\ncommands:\n";
  for (const CLI::App* c : vines->get_subcommands([](const CLI::App*) { return true; })) {
    const std::string head = "  " + c->get_name() + " ";
    out += head + wrapped_synopsis(c, head.size() + 2, head.size()) + "\n";
    out += "      " + wrap(c->get_description(), 6, 6) + "\n";
  }
  return out + "\n" + wrap(vines->get_footer(), 0, 0) + "\n";
}

// `vines help COMMAND`: usage, summary, options (then each other group's), notes.
std::string command_help(const CLI::App* cmd) {
  const std::string head = "usage: vines " + cmd->get_name() + " ";
  std::string out = head + wrapped_synopsis(cmd, head.size(), head.size()) + "\n\n";
  out += "  " + wrap(cmd->get_description(), 2, 2) + "\n\n";
  out += option_lines(cmd, kMainGroup);
  for (const std::string& g : other_groups(cmd)) out += "\n" + g + ":\n" + option_lines(cmd, g);
  if (!cmd->get_footer().empty()) out += "\n" + wrap(cmd->get_footer(), 0, 0) + "\n";
  return out;
}

class Formatter : public CLI::FormatterBase {
 public:
  std::string make_help(const CLI::App* app, std::string, CLI::AppFormatMode) const override {
    return app->get_parent() ? command_help(app) : vines_help(app);
  }
};

// The command NAME of vines, or null.
const CLI::App* find_command(const CLI::App& vines, const std::string& name) {
  const auto found = vines.get_subcommands([&](const CLI::App* c) { return c->get_name() == name; });
  return found.empty() ? nullptr : found.front();
}

std::string help_of(const CLI::App* app) { return app->get_formatter()->make_help(app, "", CLI::AppFormatMode::Normal); }

}  // namespace

void use_vines_help(CLI::App& vines) { vines.formatter(std::make_shared<Formatter>()); }

void add_help(CLI::App& vines) {
  auto command = std::make_shared<std::string>();
  add_command(vines, "help", "This text, or the options of COMMAND.", "", [&vines, command] {
    const CLI::App* of = command->empty() ? &vines : find_command(vines, *command);
    std::fputs(help_of(of).c_str(), stdout);
    return kOk;
  })->add_option("COMMAND", *command, "a command")->check(CLI::Validator(
      [&vines](std::string& name) -> std::string {
        return find_command(vines, name) ? "" : "unknown command '" + name + "'";
      }, ""));
}

int report_parse_error(const CLI::App& vines, const CLI::ParseError& e) {
  const std::vector<const CLI::App*> given = vines.get_subcommands([](const CLI::App* c) { return c->parsed(); });
  const CLI::App* cmd = given.empty() ? &vines : given.front();
  if (dynamic_cast<const CLI::CallForHelp*>(&e)) {
    std::fputs(help_of(cmd).c_str(), stdout);
    return kOk;
  }
  std::string what = e.what();
  if (given.empty()) {
    const std::vector<std::string> rest = vines.remaining();
    what = rest.empty() ? "no command given" : "unknown command '" + rest.front() + "'";
  } else if (dynamic_cast<const CLI::RequiredError*>(&e)) {
    for (const CLI::Option* o : cmd->get_options())
      if (o->get_required() && o->count() == 0) {
        what = "no " + label(o) + " given";
        break;
      }
  }
  std::fprintf(stderr, "vines: %s\n\n%s", what.c_str(), help_of(cmd).c_str());
  return kUsage;
}

}  // namespace vines::cli
