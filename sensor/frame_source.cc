#include "sensor/frame_source.h"

namespace ihs::sensor {

const char* ToString(SourceStatus status) {
  switch (status) {
    case SourceStatus::kFrame:
      return "frame";
    case SourceStatus::kTimeout:
      return "timeout";
    case SourceStatus::kEndOfStream:
      return "end of stream";
    case SourceStatus::kDisconnected:
      return "disconnected";
  }
  return "unknown";
}

}  // namespace ihs::sensor
