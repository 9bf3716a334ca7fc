import Foundation

/// SMPTE time of day as Live Link Face writes it: `HH:MM:SS:FF.mmm`, the frame `FF` within the
/// second at `rate` frames per second and `mmm` thousandths of a frame.
public struct Timecode: Equatable, Sendable, CustomStringConvertible {
    /// Seconds since midnight.
    public var seconds: Double
    /// Timecode frames per second (Live Link Face's default: 60).
    public var rate: Int

    public static let liveLinkFaceRate = 60

    public init(seconds: Double, rate: Int = Timecode.liveLinkFaceRate) {
        self.seconds = seconds
        self.rate = rate
    }

    /// The time of day of `date` in the device's time zone.
    public init(date: Date, rate: Int = Timecode.liveLinkFaceRate, calendar: Calendar = .current) {
        let midnight = calendar.startOfDay(for: date)
        self.init(seconds: date.timeIntervalSince(midnight), rate: rate)
    }

    /// Parses `HH:MM:SS:FF.mmm` (the `.mmm` part optional) at `rate`.
    public init(text: String, rate: Int = Timecode.liveLinkFaceRate) throws {
        let parts = text.split(separator: ":", omittingEmptySubsequences: false)
        let bad = CaptureError.format("not a timecode HH:MM:SS:FF.mmm: '\(text)'")
        guard parts.count == 4, rate > 0 else { throw bad }
        let frameParts = parts[3].split(separator: ".", omittingEmptySubsequences: false)
        guard frameParts.count <= 2 else { throw bad }
        let digits = { (s: Substring) -> Int? in
            s.isEmpty || !s.allSatisfy(\.isASCII) || !s.allSatisfy(\.isNumber) ? nil : Int(s)
        }
        guard let h = digits(parts[0]), let m = digits(parts[1]), let s = digits(parts[2]),
              let f = digits(frameParts[0]) else { throw bad }
        var sub = 0.0
        if frameParts.count == 2 {
            guard frameParts[1].count <= 3, let t = digits(frameParts[1]) else { throw bad }
            sub = Double(t) / pow(10, Double(frameParts[1].count))
        }
        guard h < 24, m < 60, s < 60, f < rate else {
            throw CaptureError.format("timecode field out of range: '\(text)'")
        }
        self.init(seconds: Double(h * 3600 + m * 60 + s) + (Double(f) + sub) / Double(rate), rate: rate)
    }

    /// `HH:MM:SS:FF.mmm`, rounded to the nearest thousandth of a frame (as the native writer).
    public var description: String {
        let thousandths = Int64((seconds * Double(rate) * 1000.0 + 0.5).rounded(.down))
        let frames = thousandths / 1000, milli = thousandths % 1000
        let whole = frames / Int64(rate), frame = frames % Int64(rate)
        return String(format: "%02lld:%02lld:%02lld:%02lld.%03lld",
                      whole / 3600 % 24, whole / 60 % 60, whole % 60, frame, milli)
    }
}
