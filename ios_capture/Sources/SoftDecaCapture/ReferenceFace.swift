import Foundation

/// ARKit's reference face as OBJ files (`Neutral.obj` and one `<blendshape>.obj` per ARKit
/// name, ARKit's 1,220-vertex topology): mixed by weights it gives the face mesh ARKit would
/// report, which makes synthetic takes (weights of a real take, geometry of the reference face)
/// for tests and for the command-line sender.
public struct ReferenceFace: Sendable {
    public let neutral: [SIMD3<Float>]
    /// Per canonical blendshape, the offsets from the neutral (nil: the shape is not in the folder).
    public let deltas: [[SIMD3<Float>]?]

    public init(folder: URL) throws {
        let neutralURL = folder.appendingPathComponent("Neutral.obj")
        guard FileManager.default.fileExists(atPath: neutralURL.path) else {
            throw CaptureError.format("no Neutral.obj in \(folder.path) (a folder of ARKit's reference shapes)")
        }
        neutral = try Self.vertices(neutralURL)
        var d = [[SIMD3<Float>]?]()
        for name in ARKitBlendshapes.names {
            let url = folder.appendingPathComponent(name + ".obj")
            guard FileManager.default.fileExists(atPath: url.path) else { d.append(nil); continue }
            let v = try Self.vertices(url)
            d.append(zip(v, neutral).map { $0 - $1 })
        }
        guard d.compactMap({ $0 }).count >= 3 else {
            throw CaptureError.format("\(folder.path) holds fewer than three ARKit blendshapes")
        }
        deltas = d
    }

    /// The `v x y z` lines of an OBJ file; it must have ARKit's 1,220 vertices.
    static func vertices(_ url: URL) throws -> [SIMD3<Float>] {
        guard let text = try? String(contentsOf: url, encoding: .utf8) else {
            throw CaptureError.format("cannot read \(url.path)")
        }
        var out = [SIMD3<Float>]()
        out.reserveCapacity(LandmarkProfile.arkitVertexCount)
        for line in text.split(separator: "\n") where line.hasPrefix("v ") {
            let f = line.split(separator: " ").dropFirst().prefix(3).compactMap { Double($0.trimmingCharacters(in: .whitespacesAndNewlines)) }
            guard f.count == 3 else { throw CaptureError.format("\(url.lastPathComponent): bad vertex line '\(line)'") }
            out.append(SIMD3(Float(f[0]), Float(f[1]), Float(f[2])))
        }
        guard out.count == LandmarkProfile.arkitVertexCount else {
            throw CaptureError.format("\(url.lastPathComponent) has \(out.count) vertices, ARKit's face mesh \(LandmarkProfile.arkitVertexCount)")
        }
        return out
    }

    /// neutral + sum_i w_i delta_i (accumulated in double precision).
    public func mesh(weights: [Float]) -> [SIMD3<Float>] {
        var acc = neutral.map { SIMD3<Double>(Double($0.x), Double($0.y), Double($0.z)) }
        for (w, delta) in zip(weights, deltas) where w != 0 {
            guard let delta else { continue }
            let wd = Double(w)
            for k in acc.indices {
                acc[k] += wd * SIMD3<Double>(Double(delta[k].x), Double(delta[k].y), Double(delta[k].z))
            }
        }
        return acc.map { SIMD3<Float>(Float($0.x), Float($0.y), Float($0.z)) }
    }
}

extension ReferenceFace {
    /// Gives a frame the face mesh its weights make and, when a profile is given, its landmarks.
    public func apply(to frame: inout CaptureFrame, profile: LandmarkProfile?) throws {
        frame.meshVertices = mesh(weights: frame.weights)
        if let p = profile { try frame.selectLandmarks(p) }
    }
}
