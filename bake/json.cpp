// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the JSON helpers of json.h over nlohmann::json.
#include "json.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <stdexcept>

namespace aggrelod::io {

Json jsonNumber(double v) {
    if (!std::isfinite(v)) return Json(nullptr);
    if (v == 0) return Json(0);  // also -0
    constexpr double kExactIntegers = 9007199254740992.0;  // 2^53
    if (std::fabs(v) < kExactIntegers && v == std::floor(v)) return Json(static_cast<int64_t>(v));
    return Json(v);
}

std::string jsonText(const Json& j) {
    // error_handler_t::replace: a name that is not valid UTF-8 is written with U+FFFD
    // instead of failing the whole file.
    return j.dump(2, ' ', false, nlohmann::detail::error_handler_t::replace) + "\n";
}

namespace {

struct TooDeep : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A character iterator that remembers the last character the parser read, so that a parse
/// callback knows where it is.
class TrackingIterator {
public:
    using iterator_category = std::input_iterator_tag;
    using value_type = char;
    using difference_type = std::ptrdiff_t;
    using pointer = const char*;
    using reference = const char&;

    TrackingIterator(const char* p, const char** lastRead) : p_(p), lastRead_(lastRead) {}
    reference operator*() const {
        *lastRead_ = p_;
        return *p_;
    }
    TrackingIterator& operator++() {
        ++p_;
        return *this;
    }
    TrackingIterator operator++(int) {
        TrackingIterator before = *this;
        ++p_;
        return before;
    }
    bool operator==(const TrackingIterator& other) const { return p_ == other.p_; }
    bool operator!=(const TrackingIterator& other) const { return p_ != other.p_; }

private:
    const char* p_;
    const char** lastRead_;
};

/// Line numbers of ever later positions in one text, counted incrementally.
class LineCounter {
public:
    explicit LineCounter(const char* begin) : at_(begin) {}
    int lineOf(const char* p) {
        for (; at_ < p; ++at_) line_ += *at_ == '\n';
        return line_;
    }

private:
    const char* at_;
    int line_ = 1;
};

}  // namespace

bool parseJson(const std::string& text, Json& out, std::string& error, int maxDepth, JsonLines* lines) {
    const char* lastRead = text.data();
    LineCounter counter(text.data());
    std::string topKey;  // the top-level object's member being parsed
    if (lines) {
        lines->rootLine = 0;
        lines->elementLines.clear();
    }
    const Json::parser_callback_t callback = [&](int depth, Json::parse_event_t event, Json& parsed) {
        const bool opens = event == Json::parse_event_t::object_start || event == Json::parse_event_t::array_start;
        if (opens && depth >= maxDepth)
            throw TooDeep("nesting deeper than " + std::to_string(maxDepth) + " levels");
        if (!lines) return true;
        if (event == Json::parse_event_t::key && depth == 1) topKey = parsed.is_string() ? parsed.get<std::string>() : "";
        if (depth == 0 && opens && lines->rootLine == 0) lines->rootLine = counter.lineOf(lastRead);
        if (depth == 2 && !topKey.empty() && topKey == lines->arrayKey) {
            if (event == Json::parse_event_t::object_start) lines->elementLines.push_back(counter.lineOf(lastRead));
            else if (event == Json::parse_event_t::array_start) lines->elementLines.push_back(0);
            else if (event == Json::parse_event_t::value) lines->elementLines.push_back(0);  // a scalar element
        }
        return true;
    };
    try {
        out = Json::parse(TrackingIterator(text.data(), &lastRead), TrackingIterator(text.data() + text.size(), &lastRead),
                          callback);
        return true;
    } catch (const Json::parse_error& e) {
        // "[json.exception.parse_error.101] parse error at line 3, column 23: syntax error ..."
        std::string what = e.what();
        const size_t at = what.find(" at line ");
        error = at == std::string::npos ? what : what.substr(at + 4);
    } catch (const std::exception& e) {
        error = e.what();
    }
    out = Json();
    return false;
}

}  // namespace aggrelod::io
