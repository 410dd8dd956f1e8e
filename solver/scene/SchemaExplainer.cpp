#include "scene/SchemaExplainer.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rcfd {
namespace {

using nlohmann::json;

// Schemas here are shallow; the bound only protects against a self-referencing $ref.
constexpr int kMaxSchemaDepth = 64;

std::string formatNumber(double v) {
  if (!std::isfinite(v)) return v > 0 ? "inf" : (v < 0 ? "-inf" : "nan");
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

std::string typeName(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::string: return "a string";
    case json::value_t::array: return "an array";
    case json::value_t::object: return "an object";
    case json::value_t::number_float: return "a number";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned: return "an integer";
    default: return "a value";
  }
}

bool hasType(const json& value, const std::string& type) {
  if (type == "number") return value.is_number();
  if (type == "integer") return value.is_number_integer();  // as valijson's strict types: 1.0 is not
  if (type == "string") return value.is_string();
  if (type == "boolean") return value.is_boolean();
  if (type == "object") return value.is_object();
  if (type == "array") return value.is_array();
  if (type == "null") return value.is_null();
  return false;
}

bool typeMatches(const json& value, const json& type) {
  if (type.is_string()) return hasType(value, type.get<std::string>());
  if (type.is_array()) {
    for (const auto& t : type) {
      if (t.is_string() && hasType(value, t.get<std::string>())) return true;
    }
    return false;
  }
  return true;
}

std::string typeWord(const json& type) {
  auto word = [](const std::string& t) {
    return (t == "integer" || t == "object" || t == "array") ? "an " + t : "a " + t;
  };
  if (type.is_string()) return word(type.get<std::string>());
  std::string text;
  for (const auto& t : type) {
    if (!text.empty()) text += " or ";
    text += word(t.is_string() ? t.get<std::string>() : std::string("value"));
  }
  return text;
}

std::size_t codePoints(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

std::string quotedList(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& n : names) text += (text.empty() ? "\"" : ", \"") + n + "\"";
  return text;
}

std::string lastToken(const std::string& pointer) {
  const auto slash = pointer.rfind('/');
  return slash == std::string::npos ? pointer : pointer.substr(slash + 1);
}

}  // namespace

std::string appendPointer(const std::string& pointer, const std::string& token) {
  std::string escaped;
  escaped.reserve(token.size());
  for (char c : token) {
    if (c == '~') escaped += "~0";
    else if (c == '/') escaped += "~1";
    else escaped += c;
  }
  return pointer + "/" + escaped;
}

namespace {
/// Compact JSON text, stopping once `budget` characters are written (no recursion past that).
void render(const json& value, std::string& text, std::size_t budget, int depth) {
  if (text.size() > budget) return;
  if (depth > 8) {
    text += value.is_array() ? "[...]" : "{...}";
    return;
  }
  if (value.is_array()) {
    text += '[';
    for (std::size_t i = 0; i < value.size() && text.size() <= budget; ++i) {
      if (i) text += ',';
      render(value[i], text, budget, depth + 1);
    }
    text += ']';
  } else if (value.is_object()) {
    text += '{';
    bool first = true;
    for (auto it = value.begin(); it != value.end() && text.size() <= budget; ++it) {
      if (!first) text += ',';
      first = false;
      text += json(it.key()).dump(-1, ' ', false, json::error_handler_t::replace) + ':';
      render(it.value(), text, budget, depth + 1);
    }
    text += '}';
  } else if (value.is_number_float()) {
    text += formatNumber(value.get<double>());
  } else {
    text += value.dump(-1, ' ', false, json::error_handler_t::replace);
  }
}
}  // namespace

std::string describeValue(const json& value, std::size_t maxLength) {
  std::string text;
  render(value, text, maxLength, 0);
  if (text.size() > maxLength) text = text.substr(0, maxLength) + "...";
  return text;
}

SchemaExplainer::SchemaExplainer(const json& rootSchema, ExternalResolver external)
    : root_(rootSchema), external_(std::move(external)) {}

std::vector<Violation> SchemaExplainer::explain(const json& document) const {
  std::vector<Violation> out;
  check(root_, Context{&root_}, document, "", out, 0);
  return out;
}

const json& SchemaExplainer::resolve(const json& schema, Context& ctx) const {
  const json* s = &schema;
  for (int hops = 0; s->is_object() && s->contains("$ref"); ++hops) {
    if (hops > kMaxSchemaDepth) throw std::logic_error("schema: $ref cycle");
    const std::string ref = (*s)["$ref"].get<std::string>();
    if (!ref.empty() && ref[0] == '#') {
      s = &ctx.root->at(json::json_pointer(ref.substr(1)));
    } else {
      const json* target = external_ ? external_(ref) : nullptr;
      if (!target) throw std::logic_error("schema: unresolvable $ref \"" + ref + "\"");
      ctx.root = target;
      s = target;
    }
  }
  return *s;
}

bool SchemaExplainer::matches(const json& schema, const Context& ctx, const json& value,
                              int depth) const {
  std::vector<Violation> scratch;
  check(schema, ctx, value, "", scratch, depth + 1);
  return scratch.empty();
}

void SchemaExplainer::check(const json& schemaIn, const Context& ctxIn, const json& value,
                            const std::string& pointer, std::vector<Violation>& out,
                            int depth) const {
  if (depth > kMaxSchemaDepth) throw std::logic_error("schema: nested too deeply");
  Context ctx = ctxIn;
  const json& schema = resolve(schemaIn, ctx);
  if (schema.is_boolean()) {
    if (!schema.get<bool>()) {
      out.push_back({pointer, "\"" + lastToken(pointer) + "\" is not allowed here (false schema)"});
    }
    return;
  }
  if (!schema.is_object()) return;

  if (auto t = schema.find("type"); t != schema.end() && !typeMatches(value, *t)) {
    out.push_back({pointer, "expected " + typeWord(*t) + ", got " + typeName(value) + " " +
                                describeValue(value) + " (type)"});
    return;  // every other rule would only repeat the type error
  }
  if (auto e = schema.find("enum"); e != schema.end()) {
    bool found = false;
    std::vector<std::string> names;
    for (const auto& option : *e) {
      found = found || option == value;
      names.push_back(option.is_string() ? option.get<std::string>() : option.dump());
    }
    if (!found) {
      out.push_back({pointer, describeValue(value) + " is not one of " + quotedList(names) + " (enum)"});
    }
  }
  if (auto c = schema.find("const"); c != schema.end() && *c != value) {
    out.push_back({pointer, "expected " + describeValue(*c) + ", got " + describeValue(value) + " (const)"});
  }
  if (value.is_number()) {
    const double v = value.get<double>();
    const std::string shown = describeValue(value);
    struct Bound {
      const char* keyword;
      const char* relation;
      bool (*ok)(double, double);
    };
    static const Bound bounds[] = {
        {"minimum", ">=", [](double x, double b) { return x >= b; }},
        {"exclusiveMinimum", ">", [](double x, double b) { return x > b; }},
        {"maximum", "<=", [](double x, double b) { return x <= b; }},
        {"exclusiveMaximum", "<", [](double x, double b) { return x < b; }},
    };
    // A value bounded on both sides is told the whole range, e.g. "; allowed: [1, 64]".
    std::string range;
    const auto lower = schema.contains("minimum") ? schema.find("minimum") : schema.find("exclusiveMinimum");
    const auto upper = schema.contains("maximum") ? schema.find("maximum") : schema.find("exclusiveMaximum");
    if (lower != schema.end() && upper != schema.end() && lower->is_number() && upper->is_number()) {
      range = std::string("; allowed: ") + (schema.contains("minimum") ? "[" : "(") +
              formatNumber(lower->get<double>()) + ", " + formatNumber(upper->get<double>()) +
              (schema.contains("maximum") ? "]" : ")");
    }
    for (const auto& b : bounds) {
      auto it = schema.find(b.keyword);
      if (it == schema.end() || !it->is_number()) continue;
      if (!b.ok(v, it->get<double>())) {
        out.push_back({pointer, shown + " is not " + b.relation + " " + formatNumber(it->get<double>()) +
                                    " (" + b.keyword + ")" + range});
      }
    }
  }
  if (value.is_string()) {
    if (auto m = schema.find("minLength"); m != schema.end() &&
                                           codePoints(value.get<std::string>()) < m->get<std::size_t>()) {
      out.push_back({pointer, "string " + describeValue(value) + " is shorter than " +
                                  std::to_string(m->get<std::size_t>()) + " character(s) (minLength)"});
    }
  }
  if (value.is_object()) checkObject(schema, ctx, value, pointer, out, depth);
  if (value.is_array()) checkArray(schema, ctx, value, pointer, out, depth);

  if (auto all = schema.find("allOf"); all != schema.end()) {
    for (const auto& sub : *all) check(sub, ctx, value, pointer, out, depth + 1);
  }
  if (auto cond = schema.find("if"); cond != schema.end()) {
    if (matches(*cond, ctx, value, depth)) {
      if (auto then = schema.find("then"); then != schema.end()) {
        check(*then, ctx, value, pointer, out, depth + 1);
      }
    } else if (auto otherwise = schema.find("else"); otherwise != schema.end()) {
      check(*otherwise, ctx, value, pointer, out, depth + 1);
    }
  }
  if (schema.contains("oneOf")) checkOneOf(schema, ctx, value, pointer, out, depth);
  if (auto n = schema.find("not"); n != schema.end() && matches(*n, ctx, value, depth)) {
    // "x-message" lets a schema say why, e.g. which kind of job takes a key.
    out.push_back({pointer, schema.value("x-message", describeValue(value) + " matches a schema it must not") +
                                " (not)"});
  }
}

void SchemaExplainer::checkObject(const json& schema, const Context& ctx, const json& value,
                                  const std::string& pointer, std::vector<Violation>& out,
                                  int depth) const {
  if (auto req = schema.find("required"); req != schema.end()) {
    for (const auto& key : *req) {
      const std::string k = key.get<std::string>();
      if (!value.contains(k)) {
        out.push_back({appendPointer(pointer, k), "required key \"" + k + "\" is missing (required)"});
      }
    }
  }
  const auto props = schema.find("properties");
  const auto additional = schema.find("additionalProperties");
  for (const auto& [key, member] : value.items()) {
    const std::string memberPointer = appendPointer(pointer, key);
    if (props != schema.end() && props->contains(key)) {
      check((*props)[key], ctx, member, memberPointer, out, depth + 1);
    } else if (additional != schema.end()) {
      if (additional->is_boolean() && !additional->get<bool>()) {
        std::vector<std::string> allowed;
        if (props != schema.end()) {
          for (const auto& [name, unused] : props->items()) allowed.push_back(name);
        }
        // Within a typed variant (apparatus "box" or "prismatic_spouted_bed") name the variant.
        std::string variant;
        if (props != schema.end() && props->contains("type") && (*props)["type"].contains("const")) {
          variant = " for type " + describeValue((*props)["type"]["const"]);
        }
        out.push_back({memberPointer, "unknown key \"" + key + "\"" + variant + "; allowed here: " +
                                          quotedList(allowed) + " (additionalProperties)"});
      } else {
        check(*additional, ctx, member, memberPointer, out, depth + 1);
      }
    }
  }
}

void SchemaExplainer::checkArray(const json& schema, const Context& ctx, const json& value,
                                 const std::string& pointer, std::vector<Violation>& out,
                                 int depth) const {
  const std::size_t n = value.size();
  if (auto m = schema.find("minItems"); m != schema.end() && n < m->get<std::size_t>()) {
    out.push_back({pointer, "array has " + std::to_string(n) + " item(s), needs at least " +
                                std::to_string(m->get<std::size_t>()) + " (minItems)"});
  }
  if (auto m = schema.find("maxItems"); m != schema.end() && n > m->get<std::size_t>()) {
    out.push_back({pointer, "array has " + std::to_string(n) + " item(s), allows at most " +
                                std::to_string(m->get<std::size_t>()) + " (maxItems)"});
  }
  if (auto items = schema.find("items"); items != schema.end() && (items->is_object() || items->is_boolean())) {
    for (std::size_t i = 0; i < n; ++i) {
      check(*items, ctx, value[i], appendPointer(pointer, std::to_string(i)), out, depth + 1);
    }
  }
  if (auto u = schema.find("uniqueItems"); u != schema.end() && u->is_boolean() && u->get<bool>()) {
    for (std::size_t j = 1; j < n; ++j) {
      for (std::size_t i = 0; i < j; ++i) {
        if (value[i] == value[j]) {
          out.push_back({appendPointer(pointer, std::to_string(j)),
                         "duplicate " + describeValue(value[j]) + ", already item " + std::to_string(i) +
                             " (uniqueItems)"});
          break;
        }
      }
    }
  }
}

void SchemaExplainer::checkOneOf(const json& schema, const Context& ctx, const json& value,
                                 const std::string& pointer, std::vector<Violation>& out,
                                 int depth) const {
  const json& branches = schema["oneOf"];
  std::vector<const json*> resolved;
  std::vector<Context> contexts;
  int matching = 0;
  for (const auto& branch : branches) {
    Context c = ctx;
    resolved.push_back(&resolve(branch, c));
    contexts.push_back(c);
    matching += matches(branch, ctx, value, depth) ? 1 : 0;
  }
  if (matching == 1) return;

  bool allConst = !resolved.empty();
  bool allRequired = !resolved.empty();
  for (const json* b : resolved) {
    allConst = allConst && b->is_object() && b->contains("const");
    allRequired = allRequired && b->is_object() && b->size() == 1 && b->contains("required");
  }
  if (allConst && matching == 0) {
    std::vector<std::string> names;
    for (const json* b : resolved) {
      names.push_back((*b)["const"].is_string() ? (*b)["const"].get<std::string>() : (*b)["const"].dump());
    }
    // The effect vocabulary (its entries carry "x-stage") is the const list users meet most.
    const bool effect = resolved.front()->contains("x-stage");
    std::string text = effect ? "unknown effect " : "unknown value ";
    text += describeValue(value) + "; valid " + (effect ? "effects" : "values") + " are: ";
    for (std::size_t i = 0; i < names.size(); ++i) text += (i ? ", " : "") + names[i];
    out.push_back({pointer, text});
    return;
  }
  if (allRequired) {
    std::vector<std::string> keys;
    for (const json* b : resolved) {
      for (const auto& k : (*b)["required"]) keys.push_back(k.get<std::string>());
    }
    if (matching == 0) {
      out.push_back({appendPointer(pointer, keys.front()),
                     "exactly one of " + quotedList(keys) + " is required, none is given (oneOf)"});
    } else {
      out.push_back({appendPointer(pointer, keys.back()),
                     "only one of " + quotedList(keys) + " may be given (oneOf)"});
    }
    return;
  }
  if (matching == 0) {
    // The branch whose type fits is what the author meant: report its violations alone.
    std::vector<std::size_t> typed;
    for (std::size_t i = 0; i < resolved.size(); ++i) {
      const json* b = resolved[i];
      if (b->is_object() && (!b->contains("type") || typeMatches(value, (*b)["type"]))) typed.push_back(i);
    }
    if (typed.size() == 1) {
      check(*resolved[typed.front()], contexts[typed.front()], value, pointer, out, depth + 1);
      return;
    }
  }
  std::string text = describeValue(value) + (matching == 0 ? " is none of: " : " matches more than one of: ");
  for (std::size_t i = 0; i < resolved.size(); ++i) {
    text += (i ? "; " : "") + describeSchema(*resolved[i], contexts[i]);
  }
  out.push_back({pointer, text + " (oneOf)"});
}

std::string SchemaExplainer::describeSchema(const json& schemaIn, const Context& ctxIn) const {
  Context ctx = ctxIn;
  const json& schema = resolve(schemaIn, ctx);
  if (!schema.is_object()) return schema.dump();
  std::string text = schema.contains("type") ? typeWord(schema["type"]) : std::string("a value");
  static const std::pair<const char*, const char*> bounds[] = {
      {"minimum", " >= "}, {"exclusiveMinimum", " > "}, {"maximum", " <= "}, {"exclusiveMaximum", " < "}};
  for (const auto& [keyword, relation] : bounds) {
    if (schema.contains(keyword)) text += relation + formatNumber(schema[keyword].get<double>());
  }
  if (schema.contains("items")) {
    const bool fixed = schema.contains("minItems") && schema.contains("maxItems") &&
                       schema["minItems"] == schema["maxItems"];
    if (fixed) text += " of " + schema["minItems"].dump() + " items";
    text += ", each " + describeSchema(schema["items"], ctx);
  }
  return text;
}

}  // namespace rcfd
