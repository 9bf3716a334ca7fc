import Foundation
import XCTest
@testable import SoftDecaCapture

/// Paths the tests read: the repository, the native CLI, the third-party data folder.
enum TestEnvironment {
    /// The repository root (this file is ios_capture/Tests/SoftDecaCaptureTests/Support.swift).
    static let repoRoot = URL(fileURLWithPath: #filePath)
        .deletingLastPathComponent().deletingLastPathComponent()
        .deletingLastPathComponent().deletingLastPathComponent()

    static let goldenFolder = repoRoot.appendingPathComponent("tests/golden/streaming")

    /// The third-party data (ARKit reference shapes, Live Link Face takes): SOFTDECA_DATA (set by
    /// the Makefile; `make setup` fills and verifies it), else the checkout's `.cache/data`.
    static func dataFolder() throws -> URL {
        let env = ProcessInfo.processInfo.environment
        let url = env["SOFTDECA_DATA"].flatMap { $0.isEmpty ? nil : URL(fileURLWithPath: $0) }
            ?? repoRoot.appendingPathComponent(".cache/data")
        let need = ["arkit-reference/ARKit_reference_blendshapes.zip", "recordings/livelinkface-alexdjulin/S07-001.csv"]
        for n in need where !FileManager.default.fileExists(atPath: url.appendingPathComponent(n).path) {
            throw TestFailure("the data folder \(url.path) lacks \(n): run `make setup` (or set SOFTDECA_DATA to a folder with arkit-reference/ and recordings/)")
        }
        return url
    }

    /// The native `softdeca` CLI: SOFTDECA_CLI (set by `make test-swift`), else the release build.
    static func cli() throws -> URL {
        let env = ProcessInfo.processInfo.environment
        let url = env["SOFTDECA_CLI"].flatMap { $0.isEmpty ? nil : URL(fileURLWithPath: $0) }
            ?? repoRoot.appendingPathComponent("build/release/plugin/cli/softdeca")
        guard FileManager.default.isExecutableFile(atPath: url.path) else {
            throw TestFailure("no softdeca CLI at \(url.path): run `make build` (or set SOFTDECA_CLI)")
        }
        return url
    }

    static func temporaryFolder(_ name: String) throws -> URL {
        let url = FileManager.default.temporaryDirectory
            .appendingPathComponent("softdeca-capture-tests-\(getpid())-\(name)-\(UInt32.random(in: 0...UInt32.max))")
        try FileManager.default.createDirectory(at: url, withIntermediateDirectories: true)
        return url
    }
}

struct TestFailure: Error, CustomStringConvertible {
    let description: String
    init(_ d: String) { description = d }
}

/// A golden `.txt`: `[section]` lines and `key values...` lines (tests/golden/streaming/README.md).
struct GoldenValues {
    static let textKeys: Set<String> = ["format", "kind", "drop_reason", "device_id", "subject", "profile_name",
                                        "device", "source", "clock", "units"]
    var sections: [String: [String: String]] = [:]

    init(_ url: URL) throws {
        let text = try String(contentsOf: url, encoding: .utf8)
        var section = ""
        sections[section] = [:]
        for raw in text.split(separator: "\n") {
            let line = String(raw)
            if line.hasPrefix("#") || line.isEmpty { continue }
            if line.hasPrefix("[") && line.hasSuffix("]") {
                section = String(line.dropFirst().dropLast())
                sections[section] = [:]
                continue
            }
            let key = line.prefix { $0 != " " }
            sections[section]![String(key)] = line.count > key.count ? String(line.dropFirst(key.count + 1)) : ""
        }
    }

    func text(_ key: String, in section: String = "") -> String? { sections[section]?[key] }

    func numbers(_ key: String, in section: String = "") -> [Double]? {
        text(key, in: section).map { $0.split(separator: " ").map { Double($0)! } }
    }

    func floats(_ key: String, in section: String = "") -> [Float]? { numbers(key, in: section)?.map(Float.init) }

    func number(_ key: String, in section: String = "") -> Double? { numbers(key, in: section)?.first }

    func pose(_ key: String, in section: String = "") -> Pose? {
        floats(key, in: section).map { Pose(position: SIMD3($0[0], $0[1], $0[2]), rotation: SIMD4($0[3], $0[4], $0[5], $0[6])) }
    }

    /// xyz triples after a leading count.
    func points(_ key: String, in section: String = "") -> [SIMD3<Float>]? {
        guard let v = floats(key, in: section) else { return nil }
        let n = Int(v[0])
        return (0..<n).map { SIMD3(v[1 + 3 * $0], v[2 + 3 * $0], v[3 + 3 * $0]) }
    }
}

func goldenBytes(_ name: String) throws -> [UInt8] {
    [UInt8](try Data(contentsOf: TestEnvironment.goldenFolder.appendingPathComponent(name)))
}

/// Runs a process to its end; returns stdout and stderr; throws on a nonzero exit.
@discardableResult
func runTool(_ tool: URL, _ arguments: [String], environment: [String: String] = [:], timeout: Double = 600) throws -> (out: String, err: String) {
    let p = Process()
    p.executableURL = tool
    p.arguments = arguments
    var env = ProcessInfo.processInfo.environment
    for (k, v) in environment { env[k] = v }
    p.environment = env
    // Output goes to files: a pipe the test does not drain would stall the child.
    let folder = try TestEnvironment.temporaryFolder("run")
    defer { try? FileManager.default.removeItem(at: folder) }
    let outURL = folder.appendingPathComponent("out"), errURL = folder.appendingPathComponent("err")
    _ = FileManager.default.createFile(atPath: outURL.path, contents: nil)
    _ = FileManager.default.createFile(atPath: errURL.path, contents: nil)
    p.standardOutput = try FileHandle(forWritingTo: outURL)
    p.standardError = try FileHandle(forWritingTo: errURL)
    try p.run()
    let deadline = Date().addingTimeInterval(timeout)
    while p.isRunning && Date() < deadline { Thread.sleep(forTimeInterval: 0.02) }
    if p.isRunning {
        p.terminate()
        p.waitUntilExit()
        throw TestFailure("\(tool.lastPathComponent) \(arguments.joined(separator: " ")) ran past \(timeout) s")
    }
    p.waitUntilExit()
    let outData = (try? Data(contentsOf: outURL)) ?? Data(), errData = (try? Data(contentsOf: errURL)) ?? Data()
    let o = String(decoding: outData, as: UTF8.self), e = String(decoding: errData, as: UTF8.self)
    guard p.terminationStatus == 0 else {
        throw TestFailure("\(tool.lastPathComponent) \(arguments.joined(separator: " ")) exited \(p.terminationStatus):\n\(o)\n\(e)")
    }
    return (o, e)
}
