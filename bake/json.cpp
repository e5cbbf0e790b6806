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

/// Line and column of ever later positions in one text, counted incrementally.
class LineCounter {
public:
    explicit LineCounter(const char* begin) : at_(begin), lineStart_(begin) {}
    int lineOf(const char* p) {
        for (; at_ < p; ++at_)
            if (*at_ == '\n') {
                ++line_;
                lineStart_ = at_ + 1;
            }
        return line_;
    }
    /// "line L, column C" of p (1-based).
    std::string where(const char* p) {
        const int line = lineOf(p);
        return "line " + std::to_string(line) + ", column " + std::to_string(p - lineStart_ + 1);
    }

private:
    const char* at_;
    const char* lineStart_;
    int line_ = 1;
};

/// nlohmann's DOM builder with a depth limit and the lines of JsonLines. A SAX handler, not a
/// parse callback: with a callback nlohmann rescans a container's earlier elements at every
/// close, which is quadratic in the number of elements.
class TrackingSax {
public:
    using number_integer_t = Json::number_integer_t;
    using number_unsigned_t = Json::number_unsigned_t;
    using number_float_t = Json::number_float_t;
    using string_t = Json::string_t;
    using binary_t = Json::binary_t;

    TrackingSax(Json& out, int maxDepth, JsonLines* lines, const char* text, const char*& lastRead)
        : dom_(out, true), maxDepth_(maxDepth), lines_(lines), counter_(text), lastRead_(lastRead) {}

    bool null() { return scalar() && dom_.null(); }
    bool boolean(bool v) { return scalar() && dom_.boolean(v); }
    bool number_integer(number_integer_t v) { return scalar() && dom_.number_integer(v); }
    bool number_unsigned(number_unsigned_t v) { return scalar() && dom_.number_unsigned(v); }
    bool number_float(number_float_t v, const string_t& text) { return scalar() && dom_.number_float(v, text); }
    bool string(string_t& v) { return scalar() && dom_.string(v); }
    bool binary(binary_t& v) { return scalar() && dom_.binary(v); }
    bool start_object(std::size_t n) { return open(true) && dom_.start_object(n); }
    bool key(string_t& k) {
        if (depth_ == 1) topKey_ = k;
        return dom_.key(k);
    }
    bool end_object() {
        --depth_;
        return dom_.end_object();
    }
    bool start_array(std::size_t n) { return open(false) && dom_.start_array(n); }
    bool end_array() {
        --depth_;
        return dom_.end_array();
    }
    bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& e) {
        return dom_.parse_error(position, token, e);  // throws (exceptions allowed)
    }

private:
    bool inTrackedArray() const { return lines_ && depth_ == 2 && !topKey_.empty() && topKey_ == lines_->arrayKey; }
    bool scalar() {
        if (inTrackedArray()) lines_->elementLines.push_back(0);
        return true;
    }
    bool open(bool object) {
        if (depth_ >= maxDepth_)
            throw TooDeep(counter_.where(lastRead_) + ": nesting deeper than " + std::to_string(maxDepth_) + " levels");
        if (lines_ && depth_ == 0) lines_->rootLine = counter_.lineOf(lastRead_);
        if (inTrackedArray()) lines_->elementLines.push_back(object ? counter_.lineOf(lastRead_) : 0);
        ++depth_;
        return true;
    }

    nlohmann::detail::json_sax_dom_parser<Json> dom_;
    int maxDepth_;
    JsonLines* lines_;
    LineCounter counter_;
    const char*& lastRead_;
    int depth_ = 0;
    std::string topKey_;  ///< the top-level object's member being parsed
};

}  // namespace

bool parseJson(const std::string& text, Json& out, std::string& error, int maxDepth, JsonLines* lines) {
    const char* lastRead = text.data();
    if (lines) {
        lines->rootLine = 0;
        lines->elementLines.clear();
    }
    out = Json();
    try {
        TrackingSax sax(out, maxDepth, lines, text.data(), lastRead);
        Json::sax_parse(TrackingIterator(text.data(), &lastRead), TrackingIterator(text.data() + text.size(), &lastRead),
                        &sax);
        return true;
    } catch (const Json::exception& e) {
        // "[json.exception.parse_error.101] parse error at line 3, column 23: syntax error ..."
        std::string what = e.what();
        const size_t at = what.find(" at line ");
        if (at != std::string::npos) {
            error = what.substr(at + 4);
        } else {
            LineCounter counter(text.data());  // e.g. a number out of range: say where it stopped
            const size_t tag = what.find("] ");
            error = counter.where(lastRead) + ": " + (tag == std::string::npos ? what : what.substr(tag + 2));
        }
    } catch (const std::exception& e) {
        error = e.what();
    }
    out = Json();
    return false;
}

}  // namespace aggrelod::io
