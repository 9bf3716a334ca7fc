using System;
using System.Collections.Generic;
using System.IO;
using SoftDeca;

namespace SoftDeca.Unity
{
    /// <summary>
    /// One loaded Model per bundle for every SoftDecaAvatar using it, counted by its users and
    /// disposed when the last lets go. The library batches the frames of avatars made from one
    /// Model (AvatarBatch), so the components of one bundle must share its Model. Main thread only.
    /// </summary>
    internal sealed class SharedModel
    {
        private static readonly Dictionary<string, SharedModel> loaded = new Dictionary<string, SharedModel>(StringComparer.Ordinal);

        private readonly string path;
        private int users;

        public readonly Model Model;

        private SharedModel(string path, Model model)
        {
            this.path = path;
            Model = model;
        }

        /// <summary>The bundle at path, loaded by its first user; each Acquire is matched by one Release.</summary>
        public static SharedModel Acquire(string path)
        {
            string key = Key(path);
            SharedModel shared;
            if (!loaded.TryGetValue(key, out shared))
            {
                shared = new SharedModel(key, Model.Load(path));
                loaded.Add(key, shared);
            }
            ++shared.users;
            return shared;
        }

        // One entry per bundle however its path is written ("a/b", "a/b/", "a/./b").
        private static string Key(string path)
        {
            return Path.GetFullPath(path).TrimEnd(Path.DirectorySeparatorChar, Path.AltDirectorySeparatorChar);
        }

        /// <summary>One user lets go; the last disposes the model (avatars made from it keep what they need).</summary>
        public void Release()
        {
            if (users == 0) throw new InvalidOperationException("the bundle " + path + " was released more often than acquired");
            if (--users > 0) return;
            loaded.Remove(path);
            Model.Dispose();
        }
    }
}
