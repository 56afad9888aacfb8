// Schema validation of graph files with valijson (kept in its own translation unit: it is
// heavy to compile).

#define VALIJSON_USE_EXCEPTIONS 1

#include "graph_schema.hpp"

#include <cf/types.hpp>

#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

#include <memory>

namespace cf::internal {

namespace {

/// The graph schema, or (item set) the schema of one of its definitions with the others
/// beside it for its references.
std::unique_ptr<valijson::Schema> parse_schema(const char* item) {
  auto s = std::make_unique<valijson::Schema>();
  nlohmann::json doc = nlohmann::json::parse(graph_schema_text());
  if (item != nullptr) {
    nlohmann::json sub = nlohmann::json::object();
    sub["$schema"] = doc["$schema"];
    sub["$id"] = doc["$id"];
    sub["definitions"] = doc["definitions"];
    sub["$ref"] = std::string("#/definitions/") + item;
    doc = std::move(sub);
  }
  valijson::SchemaParser parser(valijson::SchemaParser::kDraft7);
  valijson::adapters::NlohmannJsonAdapter adapter(doc);
  // The only external reference is the model schema, embedded next to this one.
  const auto fetch = [](const std::string& uri) -> const nlohmann::json* {
    const std::string name = "model.schema.json";
    if (uri.size() >= name.size() && uri.compare(uri.size() - name.size(), name.size(), name) == 0)
      return new nlohmann::json(nlohmann::json::parse(model_schema_text()));
    return nullptr;
  };
  const auto free_doc = [](const nlohmann::json* d) { delete d; };
  parser.populateSchema(adapter, *s, fetch, free_doc);
  return s;
}

const valijson::Schema& graph_schema() {
  static const std::unique_ptr<valijson::Schema> schema = parse_schema(nullptr);
  return *schema;
}

/// valijson's context is {"<root>", "[cfs]", "[3]", ...}; a JSON pointer is /cfs/3/...
std::string pointer_of(const std::vector<std::string>& context) {
  std::string p;
  for (const std::string& c : context) {
    if (c == "<root>") continue;
    std::string token = c;
    if (token.size() >= 2 && token.front() == '[' && token.back() == ']')
      token = token.substr(1, token.size() - 2);
    if (token.size() >= 2 && token.front() == '"' && token.back() == '"')
      token = token.substr(1, token.size() - 2);
    std::string escaped;  // RFC 6901
    for (char ch : token) {
      if (ch == '~')
        escaped += "~0";
      else if (ch == '/')
        escaped += "~1";
      else
        escaped += ch;
    }
    p += "/" + escaped;
  }
  return p.empty() ? "/" : p;
}

}  // namespace

namespace {

/// Validates `value` against `schema`; on a violation throws the deepest complaint, its
/// pointer prefixed by `prefix`.
void validate(const valijson::Schema& schema, const nlohmann::json& value,
              const std::string& source, const std::string& prefix) {
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(value);
  if (validator.validate(schema, target, &results)) return;
  // valijson reports the failing sub-schemas from the outside in; the deepest complaint is
  // the most specific one.
  valijson::ValidationResults::Error error, best;
  std::size_t best_depth = 0;
  bool have = false;
  while (results.popError(error)) {
    if (!have || error.context.size() > best_depth) {
      best = error;
      best_depth = error.context.size();
      have = true;
    }
  }
  const std::string pointer = pointer_of(best.context);
  throw Error("reading '" + source + "' at " +
              (prefix.empty()   ? pointer
               : pointer == "/" ? prefix
                                : prefix + pointer) +
              ": does not match the cf-graph schema: " + best.description);
}

}  // namespace

void validate_graph_schema(const nlohmann::json& document, const std::string& source) {
  validate(graph_schema(), document, source, "");
}

void validate_graph_item(const nlohmann::json& item, bool is_cf, std::size_t index,
                         const std::string& source) {
  static const std::unique_ptr<valijson::Schema> cf = parse_schema("cf");
  static const std::unique_ptr<valijson::Schema> transition = parse_schema("transition");
  validate(is_cf ? *cf : *transition, item, source,
           (is_cf ? "/cfs/" : "/transitions/") + std::to_string(index));
}

}  // namespace cf::internal
