// The receiver configuration the receiver tests start from.
#pragma once

#include "live/receiver.h"

namespace softdeca::test {

// An ephemeral port on 127.0.0.1 and a queue no test fills; frames released after `delay` seconds.
inline live::ReceiverConfig loopback(stream::Format format = stream::Format::softdeca, double delay = 0) {
  live::ReceiverConfig c;
  c.bind_address = "127.0.0.1";
  c.port = 0;
  c.format = format;
  c.delay = delay;
  c.queue_capacity = 4096;
  return c;
}

}  // namespace softdeca::test
