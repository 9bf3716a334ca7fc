// Plays a recording: a playhead in seconds from the first frame, moved by the host's clock
// times a speed, wrapping when looping; the frame at any time is interpolated (frame_interpolation.h).
// Frames stay in the file (recording_index.h) and are decoded as they are played.
#pragma once

#include <cstddef>
#include <vector>

#include "recording/recording_index.h"
#include "recording/recording_reader.h"

namespace softdeca::recording {

class Player {
 public:
  // Throws softdeca::Error (FORMAT) when the recording has no frames.
  explicit Player(RecordingIndex index);
  explicit Player(const Recording& recording);  // frames already in memory

  const RecordingMeta& recording() const { return index_.meta(); }
  std::size_t frame_count() const { return index_.frame_count(); }
  // Frame i in capture-time order.
  stream::Frame frame(std::size_t i) const { return index_.frame(i); }
  double duration() const { return duration_; }  // seconds from the first to the last frame
  double frame_time(std::size_t i) const;        // seconds from the first frame
  // The frame at `time` seconds from the first (clamped to [0, duration]), interpolated.
  stream::Frame frame_at(double time) const;

  void seek(double time);  // clamped to [0, duration]
  double position() const { return position_; }
  void set_speed(double speed);  // >= 0; 1 is real time
  double speed() const { return speed_; }
  void set_loop(bool loop) { loop_ = loop; }
  bool loop() const { return loop_; }
  // Moves the playhead by dt * speed seconds; returns true when it reached the end without
  // looping (it then stays at the end).
  bool advance(double dt);

 private:
  RecordingIndex index_;
  double start_ = 0;
  double duration_ = 0;
  double position_ = 0;
  double speed_ = 1;
  bool loop_ = false;
};

}  // namespace softdeca::recording
