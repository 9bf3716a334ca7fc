/// ARKit's tracking state as the protocol carries it.
public enum TrackingState: UInt8, Sendable {
    case lost = 0
    case tracked = 1
    case limited = 2
}

/// A rigid transform: position in metres and a unit quaternion (x, y, z, w).
public struct Pose: Equatable, Sendable {
    public var position: SIMD3<Float>
    public var rotation: SIMD4<Float>

    public static let identity = Pose(position: .zero, rotation: SIMD4(0, 0, 0, 1))

    public init(position: SIMD3<Float>, rotation: SIMD4<Float>) {
        self.position = position
        self.rotation = rotation
    }

    /// From a 4x4 rigid transform in column-major order (`simd_float4x4`'s columns flattened,
    /// as ARKit's `ARFaceAnchor.transform`): translation from the last column, rotation from the
    /// upper 3x3 (Shepperd's method, stable for every rotation).
    public init(columnMajor m: [Float]) throws {
        guard m.count == 16, m.allSatisfy(\.isFinite) else {
            throw CaptureError.invalidFrame("a transform needs 16 finite values, column-major")
        }
        func r(_ row: Int, _ col: Int) -> Double { Double(m[col * 4 + row]) }
        let trace = r(0, 0) + r(1, 1) + r(2, 2)
        var q: (Double, Double, Double, Double)
        if trace > 0 {
            let s = (trace + 1).squareRoot() * 2
            q = ((r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s, 0.25 * s)
        } else if r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2) {
            let s = (1 + r(0, 0) - r(1, 1) - r(2, 2)).squareRoot() * 2
            q = (0.25 * s, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s, (r(2, 1) - r(1, 2)) / s)
        } else if r(1, 1) > r(2, 2) {
            let s = (1 + r(1, 1) - r(0, 0) - r(2, 2)).squareRoot() * 2
            q = ((r(0, 1) + r(1, 0)) / s, 0.25 * s, (r(1, 2) + r(2, 1)) / s, (r(0, 2) - r(2, 0)) / s)
        } else {
            let s = (1 + r(2, 2) - r(0, 0) - r(1, 1)).squareRoot() * 2
            q = ((r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, 0.25 * s, (r(1, 0) - r(0, 1)) / s)
        }
        let n = (q.0 * q.0 + q.1 * q.1 + q.2 * q.2 + q.3 * q.3).squareRoot()
        guard n > 0.5 else { throw CaptureError.invalidFrame("the transform holds no rotation") }
        position = SIMD3(m[12], m[13], m[14])
        rotation = SIMD4(Float(q.0 / n), Float(q.1 / n), Float(q.2 / n), Float(q.3 / n))
    }
}

/// One captured face: what ARKit delivers per `ARFrame` for an `ARFaceAnchor`, in the
/// product's conventions (metres, ARKit's face-anchor frame, canonical blendshape order).
public struct CaptureFrame: Sendable {
    /// Seconds on the capturing device's clock (`ARFrame.timestamp`).
    public var timestamp: Double
    /// SMPTE time of day of the capture, at the take's timecode rate.
    public var timecode: Timecode
    public var tracking: TrackingState
    /// The 52 weights in canonical order (`ARKitBlendshapes.names`).
    public var weights: [Float]
    /// The face anchor in ARKit's world frame; nil: not known.
    public var head: Pose?
    /// Eye transforms relative to the face anchor (the subject's own left and right); both or neither.
    public var eyes: (left: Pose, right: Pose)?
    /// ARKit's face mesh (`ARFaceGeometry.vertices`, 1,220 in the face-anchor frame), optional.
    public var meshVertices: [SIMD3<Float>]?
    /// The positions of a landmark profile's vertices, with the profile they belong to.
    public var landmarks: (profile: LandmarkProfile, points: [SIMD3<Float>])?

    public init(timestamp: Double, timecode: Timecode, tracking: TrackingState = .tracked,
                weights: [Float] = Array(repeating: 0, count: ARKitBlendshapes.count)) {
        self.timestamp = timestamp
        self.timecode = timecode
        self.tracking = tracking
        self.weights = weights
    }

    /// A frame from weights keyed by ARKit name (`BlendShapeLocation.rawValue`); names not
    /// given are 0, an unknown name is an error.
    public init(timestamp: Double, timecode: Timecode, tracking: TrackingState = .tracked,
                weightsByName: [String: Float]) throws {
        var w = [Float](repeating: 0, count: ARKitBlendshapes.count)
        for (name, value) in weightsByName {
            guard let i = ARKitBlendshapes.index(of: name) else {
                throw CaptureError.invalidFrame("unknown ARKit blendshape name '\(name)'")
            }
            w[i] = value
        }
        self.init(timestamp: timestamp, timecode: timecode, tracking: tracking, weights: w)
    }

    /// The weight of a blendshape by ARKit name (nil for an unknown name).
    public subscript(name: String) -> Float? {
        get { ARKitBlendshapes.index(of: name).map { weights[$0] } }
        set {
            if let i = ARKitBlendshapes.index(of: name), let v = newValue { weights[i] = v }
        }
    }

    /// Fills `landmarks` with the profile's vertices of `meshVertices`.
    public mutating func selectLandmarks(_ profile: LandmarkProfile) throws {
        guard let mesh = meshVertices else {
            throw CaptureError.invalidFrame("landmarks need the face mesh's vertices")
        }
        guard mesh.count == LandmarkProfile.arkitVertexCount else {
            throw CaptureError.invalidFrame(
                "ARKit's face mesh has \(LandmarkProfile.arkitVertexCount) vertices, got \(mesh.count)")
        }
        landmarks = (profile, profile.indices.map { mesh[Int($0)] })
    }

    /// Checks what every encoder relies on: 52 finite weights, finite times and poses.
    public func validate() throws {
        guard weights.count == ARKitBlendshapes.count else {
            throw CaptureError.invalidFrame("a frame has \(ARKitBlendshapes.count) weights, got \(weights.count)")
        }
        guard timestamp.isFinite, weights.allSatisfy(\.isFinite) else {
            throw CaptureError.invalidFrame("frame time and weights must be finite")
        }
        var poses = [Pose]()
        if let h = head { poses.append(h) }
        if let e = eyes { poses += [e.left, e.right] }
        for p in poses {
            let v = [p.position.x, p.position.y, p.position.z, p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w]
            guard v.allSatisfy(\.isFinite) else { throw CaptureError.invalidFrame("pose values must be finite") }
            let n = (p.rotation * p.rotation).sum().squareRoot()
            guard n >= 0.9 && n <= 1.1 else {
                throw CaptureError.invalidFrame("a pose's rotation must be a unit quaternion (length \(n))")
            }
        }
        if let lm = landmarks {
            guard lm.points.count == lm.profile.indices.count else {
                throw CaptureError.invalidFrame(
                    "profile '\(lm.profile.name)' has \(lm.profile.indices.count) vertices, the frame \(lm.points.count) landmarks")
            }
            guard lm.points.allSatisfy({ $0.x.isFinite && $0.y.isFinite && $0.z.isFinite }) else {
                throw CaptureError.invalidFrame("landmark positions must be finite")
            }
        }
    }
}
