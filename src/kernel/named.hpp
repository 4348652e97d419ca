// Names of enumerated choices (traversals, build methods, instruction sets): one table per enum, read
// both ways. An unknown name is refused with the accepted ones listed, never mapped to a default.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "cellrt/error.hpp"

namespace cellrt::detail {

template <class E>
struct Named {
    const char* name;
    E value;
};

template <class E, std::size_t N>
std::vector<std::string> names_of(const Named<E> (&table)[N]) {
    std::vector<std::string> out;
    for (const Named<E>& n : table) out.emplace_back(n.name);
    return out;
}

// "a, b, c"
std::string join_names(const std::vector<std::string>& names);

// The value named `name`; throws cellrt::Error "`what` 'name' is not one of: ..." otherwise.
template <class E, std::size_t N>
E value_named(const Named<E> (&table)[N], std::string_view name, std::string_view what) {
    for (const Named<E>& n : table)
        if (name == n.name) return n.value;
    throw Error(std::string(what) + " '" + std::string(name) + "' is not one of: " + join_names(names_of(table)));
}

template <class E, std::size_t N>
const char* name_of(const Named<E> (&table)[N], E value) {
    for (const Named<E>& n : table)
        if (n.value == value) return n.name;
    return "?";
}

}  // namespace cellrt::detail
