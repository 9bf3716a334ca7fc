// softdeca-capture: the capture core on a desktop. Streams or records a Live Link Face CSV take
// (optionally with the face mesh and landmarks of ARKit's reference face mixed by its weights)
// exactly as the iOS app streams and records live ARKit frames.
import Foundation
import SoftDecaCapture

let usage = """
    usage: softdeca-capture stream TAKE.csv --to HOST:PORT [options]
           softdeca-capture record TAKE.csv --out FOLDER --take NAME [options]

    stream: send the take's frames at their capture times over UDP to a numeric address.
      --to HOST:PORT          receiver (IPv4 "127.0.0.1:50110", IPv6 "[::1]:50110")
      --format NAME           softdeca (default), livelinkface or ifacialmocap
      --profile NAME          landmark profile: softdeca149 (default with --reference-shapes),
                              arkit68 (needs --arkit-reference) or none
      --rate HZ               frames per second sent (default 60)
    record: write the take as the app records it: NAME.csv (Live Link Face columns), NAME.json
      (metadata) and, with --sdrec, NAME.sdrec (the project's recording format).
      --out FOLDER --take NAME
      --flush N               frames buffered before each write (default 30)
      --realtime              append at the take's capture rate (as a live capture would)
    both:
      --reference-shapes DIR  folder of ARKit's reference OBJs (Neutral.obj, <shape>.obj):
                              frames get the face mesh their weights make, and landmarks
      --arkit-reference DIR   folder with ARKit_landmarks68.txt (for --profile arkit68)
      --start N, --frames N   skip N frames, then use at most N (0: all)
    """

struct Arguments {
    var positional: [String] = []
    var options: [String: String] = [:]
    var flags: Set<String> = []
    static let flagNames: Set<String> = ["--sdrec", "--realtime", "--help", "-h"]

    init(_ args: [String]) throws {
        var i = 0
        while i < args.count {
            let a = args[i]
            if Self.flagNames.contains(a) {
                flags.insert(a)
            } else if a.hasPrefix("--") {
                guard i + 1 < args.count else { throw CaptureError.invalidConfiguration("\(a) needs a value") }
                options[a] = args[i + 1]
                i += 1
            } else {
                positional.append(a)
            }
            i += 1
        }
    }

    func int(_ name: String, _ fallback: Int) throws -> Int {
        guard let t = options[name] else { return fallback }
        guard let v = Int(t), v >= 0 else { throw CaptureError.invalidConfiguration("\(name) takes a whole number >= 0, not '\(t)'") }
        return v
    }
}

/// "127.0.0.1:50110" or "[::1]:50110".
func endpoint(_ text: String) throws -> (String, UInt16) {
    let bad = CaptureError.invalidConfiguration("--to takes HOST:PORT with a numeric host, not '\(text)'")
    guard let colon = text.lastIndex(of: ":"), let port = UInt16(text[text.index(after: colon)...]) else { throw bad }
    var host = String(text[..<colon])
    if host.hasPrefix("[") && host.hasSuffix("]") { host = String(host.dropFirst().dropLast()) }
    return (host, port)
}

func loadFrames(_ a: Arguments, profile: LandmarkProfile?) throws -> (frames: [CaptureFrame], face: ReferenceFace?) {
    guard a.positional.count == 2 else { throw CaptureError.invalidConfiguration("give one take (a Live Link Face CSV)") }
    let url = URL(fileURLWithPath: a.positional[1])
    guard let text = try? String(contentsOf: url, encoding: .utf8) else { throw CaptureError.format("cannot read \(url.path)") }
    var frames = try LiveLinkFace.parseCSV(text).frames
    let start = try a.int("--start", 0), count = try a.int("--frames", 0)
    frames = Array(frames.dropFirst(start))
    if count > 0 { frames = Array(frames.prefix(count)) }
    guard let dir = a.options["--reference-shapes"] else { return (frames, nil) }
    let face = try ReferenceFace(folder: URL(fileURLWithPath: dir))
    for k in frames.indices { try face.apply(to: &frames[k], profile: profile) }
    return (frames, face)
}

func profile(_ a: Arguments, default name: String?) throws -> LandmarkProfile? {
    let name = a.options["--profile"] ?? name
    guard let n = name, n != "none" else { return nil }
    return try LandmarkProfile.load(named: n, arkitReference: a.options["--arkit-reference"].map { URL(fileURLWithPath: $0) })
}

func stream(_ a: Arguments) throws {
    guard let to = a.options["--to"] else { throw CaptureError.invalidConfiguration("stream needs --to HOST:PORT") }
    let (host, port) = try endpoint(to)
    guard let format = StreamFormat(rawValue: a.options["--format"] ?? "softdeca") else {
        throw CaptureError.invalidConfiguration("unknown --format '\(a.options["--format"]!)' (softdeca, livelinkface, ifacialmocap)")
    }
    let defaultProfile = format == .softdeca && a.options["--reference-shapes"] != nil ? "softdeca149" : nil
    let p = try profile(a, default: defaultProfile)
    let config = CaptureConfiguration(host: host, port: port, format: format, profileName: p?.name,
                                      rate: Double(try a.int("--rate", 60)))
    try config.validate()
    let (frames, face) = try loadFrames(a, profile: p)
    let streamer = try FrameStreamer(configuration: config, transport: try POSIXUDPTransport(host: host, port: port), profile: p)
    try streamer.start(neutral: face?.neutral)
    try streamer.play(frames)
    let s = streamer.status
    print("sent \(s.framesSent) frames (\(s.datagramsSent) datagrams, \(s.sendErrors) send errors) to \(to) as \(format.rawValue), session \(streamer.sessionID)")
    if let e = s.lastError { print("last send error: \(e)") }
}

func record(_ a: Arguments) throws {
    guard let out = a.options["--out"], let take = a.options["--take"] else {
        throw CaptureError.invalidConfiguration("record needs --out FOLDER and --take NAME")
    }
    let p = try profile(a, default: a.options["--reference-shapes"] != nil ? "softdeca149" : nil)
    let (frames, face) = try loadFrames(a, profile: p)
    let recorder = try TakeRecorder(
        folder: URL(fileURLWithPath: out), take: take,
        metadata: .init(device: "softdeca-capture", subject: take, profile: p),
        flushEveryFrames: try a.int("--flush", 30), writeRecording: a.flags.contains("--sdrec"),
        neutral: face?.neutral)
    let wallStart = monotonicSeconds()
    for f in frames {
        if a.flags.contains("--realtime"), let first = frames.first {
            let wait = wallStart + (f.timestamp - first.timestamp) - monotonicSeconds()
            if wait > 0 { Thread.sleep(forTimeInterval: wait) }
        }
        try recorder.append(f)
    }
    try recorder.finish()
    print("recorded \(recorder.framesWritten) frames into \(recorder.csvURL.path)")
}

do {
    let a = try Arguments(Array(CommandLine.arguments.dropFirst()))
    if a.flags.contains("--help") || a.flags.contains("-h") || a.positional.isEmpty {
        print(usage)
        exit(a.positional.isEmpty && !a.flags.contains("--help") && !a.flags.contains("-h") ? 2 : 0)
    }
    switch a.positional[0] {
    case "stream": try stream(a)
    case "record": try record(a)
    default: throw CaptureError.invalidConfiguration("unknown command '\(a.positional[0])' (stream, record)")
    }
} catch {
    FileHandle.standardError.write(Data("softdeca-capture: \(error)\n".utf8))
    exit(1)
}
