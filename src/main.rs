fn main() {
    println!("candela");
}
