import Foundation

/// Which vertices of ARKit's face mesh a frame's landmarks are (docs/protocol.md, "Profile").
/// The id is the CRC-32 of the indices as u16 little-endian bytes, so a profile checks itself.
public struct LandmarkProfile: Equatable, Sendable {
    public static let arkitVertexCount = 1220
    /// The most landmarks a protocol frame or profile message carries (a profile may name more
    /// for recordings; streaming it is refused).
    public static let maxLandmarks = 150
    public static let maxNameBytes = 64
    /// The names `load(named:)` knows.
    public static let knownNames = ["softdeca149", "arkit68"]

    public let name: String
    public let indices: [UInt16]
    public let id: UInt32

    public init(name: String, indices: [Int]) throws {
        guard !name.isEmpty, name.utf8.count <= Self.maxNameBytes else {
            throw CaptureError.profile("a profile's name has 1 to \(Self.maxNameBytes) UTF-8 bytes: '\(name)'")
        }
        guard !indices.isEmpty, indices.count <= Self.arkitVertexCount else {
            throw CaptureError.profile("profile '\(name)' has \(indices.count) vertices; 1 to \(Self.arkitVertexCount)")
        }
        if let out = indices.first(where: { !(0..<Self.arkitVertexCount).contains($0) }) {
            throw CaptureError.profile("profile '\(name)': vertex \(out) is not below \(Self.arkitVertexCount)")
        }
        guard Set(indices).count == indices.count else {
            throw CaptureError.profile("profile '\(name)' names a vertex twice")
        }
        self.name = name
        self.indices = indices.map { UInt16($0) }
        var bytes = ByteWriter()
        for i in self.indices { bytes.u16(i) }
        self.id = CRC32.checksum(bytes.bytes)
    }

    /// Where the landmark file is found: the app's resources (`landmarks.json`, added to the
    /// app target from the repository), else the repository this source file is in.
    public static func definitionURL() -> URL? {
        if let url = Bundle.main.url(forResource: "landmarks", withExtension: "json") { return url }
        let repo = URL(fileURLWithPath: #filePath).deletingLastPathComponent().deletingLastPathComponent()
            .deletingLastPathComponent().deletingLastPathComponent()
        let url = repo.appendingPathComponent("plugin/data/landmarks.json")
        return FileManager.default.fileExists(atPath: url.path) ? url : nil
    }

    /// The landmark file every part of the product reads (plugin/data/landmarks.json, whose
    /// indices the model bundle carries too): its
    /// `landmarks[].arkit_vertex`, in order.
    public static func softdeca149(definition: URL? = nil) throws -> LandmarkProfile {
        guard let url = definition ?? definitionURL() else {
            throw CaptureError.profile("the landmark definition is missing: add plugin/data/landmarks.json to the app's resources")
        }
        let data: Data
        do { data = try Data(contentsOf: url) } catch {
            throw CaptureError.profile("cannot read the landmark definition \(url.path): \(error.localizedDescription)")
        }
        guard let root = try? JSONSerialization.jsonObject(with: data) as? [String: Any],
              let points = root["landmarks"] as? [[String: Any]] else {
            throw CaptureError.profile("\(url.path) is no landmark definition (no 'landmarks' list)")
        }
        var indices = [Int]()
        for (k, p) in points.enumerated() {
            guard let v = p["arkit_vertex"] as? Int else {
                throw CaptureError.profile("\(url.path): landmark \(k) has no integer 'arkit_vertex'")
            }
            indices.append(v)
        }
        return try LandmarkProfile(name: "softdeca149", indices: indices)
    }

    /// The standard 68-point scheme on ARKit's mesh from `ARKit_landmarks68.txt` (68 vertex
    /// indices separated by white space), the file that comes with ARKit's reference face.
    public static func arkit68(file: URL) throws -> LandmarkProfile {
        guard let text = try? String(contentsOf: file, encoding: .utf8) else {
            throw CaptureError.profile("cannot read \(file.path) (the arkit68 profile needs ARKit_landmarks68.txt)")
        }
        var indices = [Int]()
        for token in text.split(whereSeparator: { $0.isWhitespace }) {
            guard let v = Int(token) else { throw CaptureError.profile("\(file.path): '\(token)' is no vertex index") }
            indices.append(v)
        }
        guard indices.count == 68 else {
            throw CaptureError.profile("\(file.path) holds \(indices.count) indices, expected 68")
        }
        return try LandmarkProfile(name: "arkit68", indices: indices)
    }

    /// A profile by name: `softdeca149` from the landmark definition, `arkit68` from
    /// `ARKit_landmarks68.txt` in `arkitReference` (a folder).
    public static func load(named name: String, arkitReference: URL? = nil) throws -> LandmarkProfile {
        switch name {
        case "softdeca149": return try softdeca149()
        case "arkit68":
            guard let folder = arkitReference else {
                throw CaptureError.profile("arkit68 needs the folder with ARKit_landmarks68.txt")
            }
            return try arkit68(file: folder.appendingPathComponent("ARKit_landmarks68.txt"))
        default:
            throw CaptureError.profile("unknown profile '\(name)' (known: \(knownNames.joined(separator: ", ")))")
        }
    }
}
