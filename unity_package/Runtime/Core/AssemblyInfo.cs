using System.Runtime.CompilerServices;

[assembly: InternalsVisibleTo("SoftDeca.Core.Tests")]
