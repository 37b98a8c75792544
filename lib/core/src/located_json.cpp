#include "lensmith/core/located_json.h"

#include <algorithm>
#include <cctype>
#include <iterator>

namespace lensmith {

namespace {

// An input iterator over the text that publishes how many characters the parser has consumed, so
// the SAX callbacks know where in the text each token ended.
class CountingIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  CountingIterator(const char* p, const char* begin, std::size_t* consumed) : p_(p), begin_(begin), consumed_(consumed) {}
  reference operator*() const { return *p_; }
  CountingIterator& operator++() {
    ++p_;
    *consumed_ = static_cast<std::size_t>(p_ - begin_);
    return *this;
  }
  CountingIterator operator++(int) {
    CountingIterator old = *this;
    ++*this;
    return old;
  }
  [[maybe_unused]] friend bool operator==(const CountingIterator& a, const CountingIterator& b) { return a.p_ == b.p_; }
  friend bool operator!=(const CountingIterator& a, const CountingIterator& b) { return a.p_ != b.p_; }

 private:
  const char* p_;
  const char* begin_;
  std::size_t* consumed_;
};

bool is_scalar_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-';
}

}  // namespace

// SAX handler that builds the DOM and records where every value starts.
class LocatedJsonBuilder {
 public:
  using json = nlohmann::json;
  using number_integer_t = json::number_integer_t;
  using number_unsigned_t = json::number_unsigned_t;
  using number_float_t = json::number_float_t;
  using string_t = json::string_t;
  using binary_t = json::binary_t;

  LocatedJsonBuilder(LocatedJson& out, std::string_view text, const std::size_t* consumed, int max_depth)
      : out_(out), text_(text), consumed_(consumed), max_depth_(max_depth) {
    line_starts_.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] == '\n') line_starts_.push_back(i + 1);
    }
  }

  std::pair<int, int> line_col(std::size_t offset) const {
    auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    const std::size_t line_index = static_cast<std::size_t>(std::distance(line_starts_.begin(), it)) - 1;
    return {static_cast<int>(line_index + 1), static_cast<int>(offset - line_starts_[line_index] + 1)};
  }

  // Start offset of the scalar token that ends just before the current position.
  std::size_t scalar_start() const {
    std::size_t end = *consumed_;
    if (end == 0) return 0;
    std::size_t q = end - 1;
    if (!is_scalar_char(text_[q]) && q > 0) --q;  // the lexer read one character of lookahead
    while (q > 0 && is_scalar_char(text_[q - 1])) --q;
    return q;
  }
  // Start offset of the string token whose closing quote was just consumed.
  std::size_t string_start() const {
    std::size_t end = *consumed_;
    if (end < 2) return 0;
    std::size_t q = end - 2;  // character before the closing quote
    while (q > 0) {
      if (text_[q] == '"') {
        std::size_t backslashes = 0;
        while (q >= backslashes + 1 && text_[q - backslashes - 1] == '\\') ++backslashes;
        if (backslashes % 2 == 0) return q;
      }
      --q;
    }
    return 0;
  }
  std::size_t bracket_start() const { return *consumed_ == 0 ? 0 : *consumed_ - 1; }

  bool null() { return add(json(nullptr), scalar_start()); }
  bool boolean(bool v) { return add(json(v), scalar_start()); }
  bool number_integer(number_integer_t v) { return add(json(v), scalar_start()); }
  bool number_unsigned(number_unsigned_t v) { return add(json(v), scalar_start()); }
  bool number_float(number_float_t v, const string_t&) { return add(json(v), scalar_start()); }
  bool string(string_t& v) { return add(json(std::move(v)), string_start()); }
  bool binary(binary_t&) { return fail_at(bracket_start(), "binary values are not JSON"); }

  bool start_object(std::size_t) {
    if (!add(json::object(), bracket_start())) return false;
    return push();
  }
  bool key(string_t& k) {
    Frame& f = stack_.back();
    if (f.value->contains(k)) {
      return fail_at(string_start(), "duplicate key \"" + k + "\"");
    }
    f.key = k;
    return true;
  }
  bool end_object() {
    stack_.pop_back();
    return true;
  }
  bool start_array(std::size_t) {
    if (!add(json::array(), bracket_start())) return false;
    return push();
  }
  bool end_array() {
    stack_.pop_back();
    return true;
  }
  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception& ex) {
    // nlohmann's message looks like "[json.exception.parse_error.101] parse error at line 1,
    // column 5: syntax error while parsing value - invalid literal; last read: 'tru'"; keep the
    // part after "parse error ...: ".
    std::string what = ex.what();
    auto colon = what.find(": ", what.find("parse error"));
    if (colon != std::string::npos) what = what.substr(colon + 2);
    (void)last_token;
    const std::size_t offset = position == 0 ? 0 : std::min(position - 1, text_.size());
    return fail_at(offset, what);
  }

  [[noreturn]] void throw_error() const { throw FileError(error_where_, error_message_); }
  bool failed() const { return !error_message_.empty(); }

 private:
  struct Frame {
    json* value;
    std::string pointer;
    std::string key;
    std::size_t next_index = 0;
  };

  bool push() {
    if (static_cast<int>(stack_.size()) >= max_depth_) {
      return fail_at(bracket_start(), "nesting deeper than " + std::to_string(max_depth_) + " levels");
    }
    stack_.push_back(Frame{last_value_, last_pointer_, {}, 0});
    return true;
  }

  bool add(json v, std::size_t start_offset) {
    std::string pointer;
    json* slot = nullptr;
    if (stack_.empty()) {
      out_.root_ = std::move(v);
      slot = &out_.root_;
    } else {
      Frame& f = stack_.back();
      if (f.value->is_object()) {
        pointer = f.pointer + "/" + json_pointer_escape(f.key);
        slot = &((*f.value)[f.key] = std::move(v));
      } else {
        pointer = f.pointer + "/" + std::to_string(f.next_index++);
        f.value->push_back(std::move(v));
        slot = &f.value->back();
      }
    }
    out_.positions_[pointer] = line_col(std::min(start_offset, text_.size()));
    last_value_ = slot;
    last_pointer_ = pointer;
    return true;
  }

  bool fail_at(std::size_t offset, const std::string& message) {
    auto [line, col] = line_col(std::min(offset, text_.size()));
    error_where_ = SourceLocation{out_.file_name_, line, col};
    error_message_ = message;
    return false;
  }

  LocatedJson& out_;
  std::string_view text_;
  const std::size_t* consumed_;
  int max_depth_;
  std::vector<std::size_t> line_starts_;
  std::vector<Frame> stack_;
  json* last_value_ = nullptr;
  std::string last_pointer_;
  SourceLocation error_where_;
  std::string error_message_;
};

LocatedJson LocatedJson::parse(std::string_view text, const std::string& file_name, int max_depth) {
  LocatedJson doc;
  doc.file_name_ = file_name;
  std::size_t consumed = 0;
  LocatedJsonBuilder builder(doc, text, &consumed, max_depth);
  CountingIterator first(text.data(), text.data(), &consumed);
  CountingIterator last(text.data() + text.size(), text.data(), &consumed);
  const bool ok = nlohmann::json::sax_parse(first, last, &builder, nlohmann::json::input_format_t::json, true, false);
  if (!ok || builder.failed()) {
    if (builder.failed()) builder.throw_error();
    throw FileError({file_name, 0, 0}, "not valid JSON");
  }
  return doc;
}

SourceLocation LocatedJson::where(const std::string& pointer) const {
  auto it = positions_.find(pointer);
  if (it == positions_.end()) return SourceLocation{file_name_, 0, 0};
  return SourceLocation{file_name_, it->second.first, it->second.second};
}

std::string json_type_phrase(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null: return "null";
    case nlohmann::json::value_t::object: return "an object";
    case nlohmann::json::value_t::array: return "an array";
    case nlohmann::json::value_t::string: return "a string (\"" + value.get<std::string>().substr(0, 40) + "\")";
    case nlohmann::json::value_t::boolean: return value.get<bool>() ? "true" : "false";
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
    case nlohmann::json::value_t::number_float: return "a number (" + value.dump() + ")";
    default: return "an unsupported value";
  }
}

std::string json_pointer_escape(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

JsonObjectReader::JsonObjectReader(const LocatedJson& doc, std::string pointer, std::string display_path)
    : doc_(doc), pointer_(std::move(pointer)), path_(std::move(display_path)) {
  object_ = &doc.root().at(nlohmann::json::json_pointer(pointer_));
  if (!object_->is_object()) {
    throw FileError(doc_.where(pointer_),
                        (path_.empty() ? std::string("the file") : path_) + ": expected an object, got " + json_type_phrase(*object_));
  }
}

bool JsonObjectReader::has(const std::string& key) const { return object_->contains(key); }

const nlohmann::json* JsonObjectReader::get(const std::string& key) {
  auto it = object_->find(key);
  if (it == object_->end()) return nullptr;
  consumed_.push_back(key);
  return &*it;
}

std::string JsonObjectReader::child_pointer(const std::string& key) const { return pointer_ + "/" + json_pointer_escape(key); }
std::string JsonObjectReader::child_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

SourceLocation JsonObjectReader::where(const std::string& key) const {
  if (!key.empty() && has(key)) return doc_.where(child_pointer(key));
  return doc_.where(pointer_);
}

void JsonObjectReader::fail(const std::string& key, const std::string& message) const {
  const std::string path = key.empty() ? path_ : child_path(key);
  throw FileError(where(key), (path.empty() ? std::string() : path + ": ") + message);
}

double JsonObjectReader::get_number(const std::string& key) {
  auto v = get_optional_number(key);
  if (!v) fail(key, "missing; expected a number");
  return *v;
}

std::optional<double> JsonObjectReader::get_optional_number(const std::string& key) {
  const nlohmann::json* v = get(key);
  if (!v) return std::nullopt;
  if (!v->is_number()) fail(key, "expected a number, got " + json_type_phrase(*v));
  return v->get<double>();
}

std::string JsonObjectReader::get_string(const std::string& key) {
  auto v = get_optional_string(key);
  if (!v) fail(key, "missing; expected a string");
  return *v;
}

std::optional<std::string> JsonObjectReader::get_optional_string(const std::string& key) {
  const nlohmann::json* v = get(key);
  if (!v) return std::nullopt;
  if (!v->is_string()) fail(key, "expected a string, got " + json_type_phrase(*v));
  return v->get<std::string>();
}

std::optional<bool> JsonObjectReader::get_optional_bool(const std::string& key) {
  const nlohmann::json* v = get(key);
  if (!v) return std::nullopt;
  if (!v->is_boolean()) fail(key, "expected true or false, got " + json_type_phrase(*v));
  return v->get<bool>();
}

std::size_t JsonObjectReader::get_array_size(const std::string& key) {
  const nlohmann::json* v = get(key);
  if (!v) fail(key, "missing; expected an array");
  if (!v->is_array()) fail(key, "expected an array, got " + json_type_phrase(*v));
  return v->size();
}

void JsonObjectReader::finish(const std::vector<std::string>& allowed_keys) const {
  for (auto it = object_->begin(); it != object_->end(); ++it) {
    if (std::find(consumed_.begin(), consumed_.end(), it.key()) != consumed_.end()) continue;
    std::string allowed;
    for (const auto& k : allowed_keys) allowed += (allowed.empty() ? "" : ", ") + k;
    fail(it.key(), "unknown key; allowed keys here: " + allowed);
  }
}

}  // namespace lensmith
