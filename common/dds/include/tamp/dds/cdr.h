#pragma once
/// @file
/// A message as CDR bytes and back, for what a service keeps on disk between its runs (the
/// execution monitor's record outbox, perception's checkpoint): the message's own type support,
/// so the bytes are exactly what travels on the wire.

#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>

#include <fastrtps/rtps/common/SerializedPayload.h>

#include "tamp/dds/topics.h"

namespace tamp::dds {

/// `m` as CDR bytes. Throws std::runtime_error when its type support cannot serialize it.
template <class T>
std::string toCdr(const T& m) {
  typename TypeSupport<T>::type type;
  auto* data = const_cast<T*>(&m);
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
  if (!type.serialize(data, &payload)) throw std::runtime_error("cannot serialize a message to CDR");
  return std::string(reinterpret_cast<const char*>(payload.data), payload.length);
}

/// The message in `bytes`, or nullopt when they are not one (truncated, another type).
template <class T>
std::optional<T> fromCdr(const std::string& bytes) {
  typename TypeSupport<T>::type type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<uint32_t>(bytes.size()));
  if (!bytes.empty()) std::memcpy(payload.data, bytes.data(), bytes.size());
  payload.length = static_cast<uint32_t>(bytes.size());
  T m;
  try {
    if (!type.deserialize(&payload, &m)) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;  // Fast CDR throws on a buffer that ends early
  }
  return m;
}

}  // namespace tamp::dds
